"""Filter values the pairs point in (`--filters acted+raised`, the default): the kinds of
the changed objects where they are at most two, and a landmark the moved objects end
beside, raised to the threshold; on programs run by the reference machine."""

from __future__ import annotations

import numpy as np
import pytest

from argpred.acted import (LANDMARK_PAIRS, SUPPORT, changed_kinds, landmarks, raised_values, stays,
                           with_filters)
from tests.helpers import reference_pairs
from search.arguments import argument_logp, used_values
from vccjax.machine.instructions import COLORS, OP, SHAPES
from vccjax.machine.scene import Scene, SceneObject

MOVE = "move_hand_to_attended_object; grab_object; {move}; release_object"
TWO_KINDS = ("scene_parse; set_color_attn(yellow); loop_start; top_down_attend; " + MOVE.format(move="move_hand_left")
             + "; next_object; loop_end; reset_attn; set_color_attn(green); loop_start; top_down_attend; "
             + MOVE.format(move="move_hand_right") + "; next_object; loop_end")
TOUCH = ("scene_parse; set_shape_attn(star); top_down_attend; move_hand_to_attended_object; grab_object; "
         "reset_attn; set_shape_attn(circle); top_down_attend; move_hand_to_attended_object; release_object")


def _scenes(n: int, seed: int, must: tuple[tuple[str, str | None], ...] = (), shapes: tuple[str, ...] = SHAPES,
            count: tuple[int, int] = (4, 6)) -> list[Scene]:
    """`n` scenes of `count` objects (at least, at most) apart from each other, each holding the (shape, colour)
    kinds in `must` (a colour None: one per scene in turn) and otherwise objects of
    `shapes` in any colour."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        k = int(rng.integers(count[0], count[1] + 1))
        kinds = [(s, c or COLORS[len(out) % len(COLORS)]) for s, c in must] + [
            (shapes[rng.integers(len(shapes))], COLORS[rng.integers(len(COLORS))]) for _ in range(k - len(must))]
        cells = rng.permutation(16)[:k]  # a 4 x 4 grid's cells, jittered: objects never touch
        xy = [(0.2 + 0.2 * (i % 4) + rng.uniform(-0.03, 0.03), 0.2 + 0.2 * (i // 4) + rng.uniform(-0.03, 0.03))
              for i in cells]
        out.append(Scene(tuple(SceneObject(s, c, x, y, 0.08) for (s, c), (x, y) in zip(kinds, xy))))
    return out


def _probs(shape: dict[str, float], color: dict[str, float]) -> dict[str, np.ndarray]:
    return {"set_shape_attn": np.array([shape.get(v, 0.0) for v in SHAPES]),
            "set_color_attn": np.array([color.get(v, 0.0) for v in COLORS])}


def test_two_filtered_kinds_changed_raise_the_weak_one_the_network_supports():
    """"All yellow left AND all green right": only yellow and green objects change, so a
    green the network reads at 0.3 is raised to the threshold; a colour no changed object
    has, or one under `SUPPORT`, is not."""
    pairs = reference_pairs(TWO_KINDS, _scenes(6, 0, (("square", "yellow"), ("circle", "green"))))
    assert len(pairs) >= 5
    kinds = changed_kinds(pairs, "color")
    assert kinds == {"yellow", "green"}  # both kinds move in some pair (each scene holds one of each)
    got = with_filters(_probs({}, {"yellow": 0.9, "green": 0.3, "blue": 0.3}), pairs, "acted+raised")
    color = dict(zip(COLORS, got["set_color_attn"]))
    assert color["yellow"] == 0.9 and color["green"] == 0.55 and color["blue"] == 0.3
    assert with_filters(_probs({}, {"green": 0.3}), pairs, "acted+raised", threshold=0.7)["set_color_attn"].max() == 0.7
    weak = with_filters(_probs({}, {"green": SUPPORT / 2}), pairs, "acted+raised")["set_color_attn"]
    assert weak.max() == SUPPORT / 2
    # 'acted' only rules out; 'network' leaves all as it was
    assert dict(zip(COLORS, with_filters(_probs({}, {"green": 0.3}), pairs, "acted")["set_color_attn"]))["green"] == 0.3


def test_many_kinds_changed_point_to_no_filter():
    """Every object moves up: the changed objects span the colours, no value is raised."""
    pairs = reference_pairs("scene_parse; loop_start; top_down_attend; " + MOVE.format(move="move_hand_up")
                   + "; next_object; loop_end", _scenes(6, 1))
    assert len(changed_kinds(pairs, "color")) >= 3
    assert raised_values(_probs({v: 0.5 for v in SHAPES}, {v: 0.5 for v in COLORS}), pairs) == \
        {"set_shape_attn": set(), "set_color_attn": set()}


def test_a_landmark_the_moved_object_ends_beside_is_raised_from_enough_pairs():
    """"Move the star to touch the circle": the circle (of any colour) is nearest to where
    the star ends in every pair (one other object in each scene), so circle is raised
    however low the network reads it; no colour is, and fewer than `LANDMARK_PAIRS` pairs
    point to none."""
    pairs = reference_pairs(TOUCH, _scenes(8, 2, (("star", "red"), ("circle", None)), ("square", "triangle", "diamond"),
                                  (3, 3)))
    assert len(pairs) >= LANDMARK_PAIRS
    for a, b in pairs:  # the star moved, the circle stayed
        assert [o.shape for o in a.objects if not stays(o, b, 0.01)] == ["star"]
    assert landmarks(pairs, "shape") == {"circle"}
    assert landmarks(pairs, "color") == set()
    assert landmarks(pairs[:LANDMARK_PAIRS - 1], "shape") == set()
    got = with_filters(_probs({"star": 0.9, "circle": 0.05}, {}), pairs, "acted+raised")
    assert dict(zip(SHAPES, got["set_shape_attn"]))["circle"] == 0.55
    acted = with_filters(_probs({"circle": 0.05}, {}), pairs, "acted")["set_shape_attn"]
    assert dict(zip(SHAPES, acted))["circle"] == 0.05


def test_the_search_takes_raised_values_by_default():
    from argpred.predict import THRESHOLD, default_predictor

    pairs = reference_pairs(TWO_KINDS, _scenes(10, 3, (("square", "yellow"), ("circle", "green"))))
    network = dict(zip(COLORS, default_predictor().for_pairs(pairs)["set_color_attn"]))
    lp = dict(zip(COLORS, argument_logp("predicted", pairs)[OP["set_color_attn"]]))
    for v in ("yellow", "green"):
        assert np.isfinite(lp[v]) == (network[v] >= SUPPORT), (v, network[v])
    plain = dict(zip(COLORS, argument_logp("predicted", pairs, filters="acted")[OP["set_color_attn"]]))
    assert all(np.isfinite(plain[v]) == (network[v] >= THRESHOLD) for v in ("yellow", "green"))
    with pytest.raises(ValueError, match="--filters must be one of"):
        argument_logp("predicted", pairs, filters="raised")


def test_on_the_546_concepts_the_values_raised_are_those_their_programs_use():
    """Against the reference programs: raising never drops a value, brings in values the
    concepts' programs give those filters, and at least as many of them as values the
    programs never use (each of those widens a search)."""
    from argpred.predict import default_predictor
    from vccjax.world.concepts import concept_names, reference_program
    from vccjax.world.dataset import dataset_for

    names = concept_names()
    ds = dataset_for(names, 0, None, progress=False)
    predictor = default_predictor()
    raised = used = 0
    for c in names:
        pairs = ds.pairs(c, "train")
        probs = predictor.for_pairs(pairs)
        acted, both = with_filters(probs, pairs, "acted"), with_filters(probs, pairs, "acted+raised")
        for name, domain in (("set_shape_attn", SHAPES), ("set_color_attn", COLORS)):
            assert (both[name] >= acted[name]).all(), (c, name)
            up = {v for v, a, b in zip(domain, acted[name], both[name]) if b > a}
            raised += len(up)
            used += len(up & {domain[i] for i in used_values(reference_program(c), name)})
    assert used >= 3 and used >= raised - used, (used, raised)
