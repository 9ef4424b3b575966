"""Filter values the objects acted on rule out (`argpred.acted`), and the search taking
them so (`--filters acted`, the default) or the network's alone."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from argpred.acted import SPAN, allowed_values, stays, with_filters
from tests.helpers import reference_pairs
from search.arguments import argument_logp, used_values
from vccjax.machine.instructions import COLORS, OP, SHAPES
from vccjax.machine.scene import Scene, SceneObject

SQ, CI, TR, ST = "square", "circle", "triangle", "star"


def _scene(*objs: tuple[str, str, float, float]) -> Scene:
    return Scene(tuple(SceneObject(s, c, x, y, 0.08) for s, c, x, y in objs))


SCENES = [
    _scene((SQ, "red", 0.2, 0.8), (CI, "green", 0.5, 0.5), (TR, "blue", 0.8, 0.7), (ST, "yellow", 0.3, 0.3)),
    _scene((CI, "red", 0.7, 0.8), (SQ, "blue", 0.2, 0.6), (ST, "green", 0.5, 0.3), (TR, "red", 0.8, 0.4)),
    _scene((TR, "yellow", 0.2, 0.8), (ST, "blue", 0.6, 0.6), (SQ, "green", 0.4, 0.3), (CI, "red", 0.8, 0.2)),
]


def test_every_object_changed_leaves_no_filter_value_and_few_kinds_leave_any():
    before = SCENES[0]
    moved_all = _scene(*((o.shape, o.color, o.x, o.y - 0.1) for o in before.objects))
    assert all(not stays(o, moved_all, 0.01) for o in before.objects)
    assert allowed_values([(before, moved_all)]) == {"set_shape_attn": set(), "set_color_attn": set()}
    # two kinds changed (as "all yellow left AND all green right"): any value stays possible
    two = _scene(*((o.shape, o.color, o.x, o.y - 0.1 * (o.color in ("green", "yellow"))) for o in before.objects))
    assert allowed_values([(before, two)]) == {"set_shape_attn": None, "set_color_attn": None}
    assert SPAN == 3


def test_a_landmark_left_in_place_keeps_its_value():
    """"Move every object to the red one": the changed objects span every colour, the
    red landmark stays put in every pair, so red is the one colour filter kept."""
    pairs = []
    for i, dy in enumerate((0.1, 0.15, 0.05)):
        objs = [(SQ, "red", 0.5, 0.2)] + [(s, c, 0.2 + 0.2 * k, 0.7) for k, (s, c) in
                                          enumerate([(CI, "green"), (TR, "blue"), (ST, "yellow")][i:] +
                                                    [(CI, "green"), (TR, "blue"), (ST, "yellow")][:i])]
        before = _scene(*objs)
        after = _scene(objs[0], *((s, c, x, y - dy) for s, c, x, y in objs[1:]))
        pairs.append((before, after))
    got = allowed_values(pairs)
    assert got["set_color_attn"] == {"red"} and got["set_shape_attn"] == {SQ}


@pytest.mark.parametrize("attr,instruction", [("shape", "set_shape_attn"), ("color", "set_color_attn")])
def test_programs_through_one_filter_keep_its_value_on_the_reference_machine(attr, instruction):
    """Whatever a filter picks, a program acting through it keeps the filter's value: each
    value of each filter, a loop over what it attends and single acts, every scene."""
    values = SHAPES if attr == "shape" else COLORS
    bodies = ["move_hand_to_attended_object; grab_object; move_hand_up; release_object",
              "fill_color(blue)", "remove_from_imagine_buffer"]
    tried = 0
    for v, body in itertools.product(values, bodies):
        for looped in (True, False):
            text = (f"scene_parse; {instruction}({v}); loop_start; top_down_attend; {body}; next_object; loop_end"
                    if looped else f"scene_parse; {instruction}({v}); top_down_attend; {body}")
            scenes = [s for s in SCENES if any(getattr(o, attr) == v for o in s.objects)]
            if not scenes:
                continue
            pairs = reference_pairs(text, scenes)
            if not pairs:
                continue
            got = allowed_values(pairs)[instruction]
            assert got is None or v in got, text
            tried += 1
    assert tried >= len(values) * len(bodies)
    # two filtered parts ("all yellow left AND all green right"): both values kept
    for v, w in itertools.combinations(values, 2):
        loop = "loop_start; top_down_attend; move_hand_to_attended_object; grab_object; move_hand_up; " \
               "release_object; next_object; loop_end"
        text = f"scene_parse; {instruction}({v}); {loop}; reset_attn; {instruction}({w}); {loop}"
        pairs = reference_pairs(text, SCENES)
        got = allowed_values(pairs)[instruction]
        assert pairs and (got is None or {v, w} <= got), (v, w)


def test_on_the_546_concepts_no_filter_value_their_programs_use_is_ruled_out():
    """The rule against the reference programs (not against any result file)."""
    from vccjax.world.concepts import concept_names, reference_program
    from vccjax.world.dataset import dataset_for

    names = concept_names()
    ds = dataset_for(names, 0, None, progress=False)
    restricted = 0
    for c in names:
        allowed = allowed_values(ds.pairs(c, "train"))
        for name, domain in (("set_shape_attn", SHAPES), ("set_color_attn", COLORS)):
            used = {domain[v] for v in used_values(reference_program(c), name)}
            assert allowed[name] is None or used <= allowed[name], (c, name, used, allowed[name])
            restricted += allowed[name] is not None
    assert restricted >= 20  # the rule does act on these concepts


def test_the_search_drops_ruled_out_filters_by_default_or_keeps_the_networks():
    from argpred.predict import THRESHOLD, default_predictor

    before = SCENES[0]
    moved_all = [(s, _scene(*((o.shape, o.color, o.x, o.y - 0.1) for o in s.objects))) for s in SCENES]
    for f in ("set_shape_attn", "set_color_attn"):
        lp = argument_logp("predicted", moved_all)[OP[f]]
        assert (lp == -np.inf).all(), f  # left out of the search
        network = default_predictor().for_pairs(moved_all)[f]
        lp = argument_logp("predicted", moved_all, filters="network")[OP[f]]
        assert np.isfinite(lp).tolist() == (network >= THRESHOLD).tolist()
        # `vcc learn`'s fallback does not bring back a value the pairs rule out (and no NaN)
        lp = argument_logp("predicted", moved_all, fallback=True)[OP[f]]
        assert (lp == -np.inf).all() and not np.isnan(lp).any()
    probs = {"set_shape_attn": np.ones(len(SHAPES)), "set_color_attn": np.ones(len(COLORS))}
    assert with_filters(probs, moved_all, "network") is probs
    assert with_filters(probs, [(before, before)], "acted")["set_color_attn"].tolist() == [1.0] * len(COLORS)
    with pytest.raises(ValueError, match="--filters must be one of"):
        with_filters(probs, moved_all, "both")
