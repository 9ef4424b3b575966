"""fill_color's arguments from the colours objects gain (`argpred.gained`), and the
search taking them so (`--fill gained`, the default) or from the network."""

from __future__ import annotations

import numpy as np
import pytest

from argpred.gained import fill_probabilities, gained_colours, with_fill
from search.arguments import argument_logp, used_values
from vccjax.machine.instructions import COLORS, OP
from vccjax.machine.reference import RefMachine
from vccjax.machine.program import parse
from vccjax.machine.scene import Scene, SceneObject

SQ, CI = "square", "circle"


def _scene(*objs: tuple[str, str, float, float]) -> Scene:
    return Scene(tuple(SceneObject(s, c, x, y, 0.08) for s, c, x, y in objs))


def test_a_move_a_swap_and_a_removal_gain_no_colour_a_recolouring_does():
    before = _scene((SQ, "red", 0.5, 0.5), (CI, "green", 0.2, 0.2))
    moved = _scene((SQ, "red", 0.8, 0.5), (CI, "green", 0.2, 0.2))
    # the circle moves onto the cell the square left: a network looking cell by cell sees
    # green appear where red was, a recolouring; the objects kept their colours
    swapped = _scene((SQ, "red", 0.8, 0.5), (CI, "green", 0.5, 0.5))
    removed = _scene((CI, "green", 0.2, 0.2))
    recoloured = _scene((SQ, "blue", 0.5, 0.5), (CI, "green", 0.2, 0.2))
    for after in (moved, swapped, removed):
        assert gained_colours([(before, after)]) == []
    assert gained_colours([(before, recoloured)]) == ["blue"]
    # a square turned green beside a green circle: one more green square, so green is gained
    assert gained_colours([(before, _scene((SQ, "green", 0.5, 0.5), (CI, "green", 0.2, 0.2)))]) == ["green"]
    # over several pairs: the union, in COLORS order
    assert gained_colours([(before, recoloured), (before, moved),
                           (before, _scene((SQ, "red", 0.5, 0.5), (CI, "yellow", 0.2, 0.2)))]) == ["blue", "yellow"]
    assert fill_probabilities([(before, recoloured)]).tolist() == [float(c == "blue") for c in COLORS]


def test_on_the_546_concepts_the_gained_colours_are_the_fill_arguments_of_their_programs():
    """The rule against the reference programs (not against any result file): each
    concept's training pairs gain exactly the colours its program fills with."""
    from vccjax.world.concepts import concept_names, reference_program
    from vccjax.world.dataset import dataset_for

    names = concept_names()
    ds = dataset_for(names, 0, None, progress=False)
    fills = 0
    for c in names:
        used = [COLORS[v] for v in sorted(set(used_values(reference_program(c), "fill_color")))]
        assert gained_colours(ds.pairs(c, "train")) == used, c
        fills += bool(used)
    assert 40 <= fills <= len(names) - 400  # both kinds are there to be told apart


def test_programs_run_on_the_reference_machine_gain_what_they_fill():
    scenes = [_scene((SQ, "red", 0.3, 0.7), (CI, "green", 0.6, 0.3), (SQ, "blue", 0.8, 0.8)),
              _scene((CI, "red", 0.2, 0.2), (SQ, "yellow", 0.7, 0.6))]
    cases = {
        "scene_parse; set_color_attn(red); top_down_attend; fill_color(blue)": ["blue"],
        "scene_parse; loop_start; top_down_attend; fill_color(yellow); next_object; loop_end": ["yellow"],
        "scene_parse; top_down_attend; move_hand_to_attended_object; grab_object; move_hand_left; "
        "release_object": [],
        "scene_parse; set_shape_attn(circle); top_down_attend; remove_from_imagine_buffer": [],
    }
    for text, gained in cases.items():
        p = parse(text)
        pairs = []
        for s in scenes:
            m = RefMachine(s).run(p)
            assert not m.failed, text
            pairs.append((s, m.output_scene()))
        assert gained_colours(pairs) == gained, text


def test_the_search_takes_fill_arguments_from_the_pairs_by_default_or_from_the_network():
    before = _scene((SQ, "red", 0.5, 0.5), (CI, "green", 0.2, 0.2))
    pairs = [(before, _scene((SQ, "blue", 0.5, 0.5), (CI, "green", 0.2, 0.2)))] * 3
    lp = argument_logp("predicted", pairs)[OP["fill_color"]]
    assert np.isfinite(lp).tolist() == [c == "blue" for c in COLORS] and lp[COLORS.index("blue")] == 0.0
    moved = [(before, _scene((SQ, "red", 0.8, 0.5), (CI, "green", 0.5, 0.5)))] * 3
    assert not np.isfinite(argument_logp("predicted+fixation", moved, parse("scene_parse; top_down_attend"))[
        OP["fill_color"]]).any()  # nothing gained: fill_color left out of the search
    # `vcc learn` falls back on the network where no argument passes; not for the exact rule
    lp = argument_logp("predicted", moved, fallback=True)[OP["fill_color"]]
    assert (lp == -np.inf).all()
    for op, v in argument_logp("predicted", moved, fallback=True).items():
        assert not np.isnan(v).any(), op
    from argpred.predict import THRESHOLD, default_predictor

    network = default_predictor().for_pairs(moved)["fill_color"]
    lp = argument_logp("predicted", moved, fill="predicted")[OP["fill_color"]]
    assert np.isfinite(lp).tolist() == (network >= THRESHOLD).tolist()
    assert with_fill({"fill_color": network}, moved, "predicted")["fill_color"] is network
    with pytest.raises(ValueError, match="--fill must be one of"):
        with_fill({}, moved, "both")
