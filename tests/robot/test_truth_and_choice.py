"""The parse checked against the true scene, and which concepts the arm's suite runs."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from robot.choice import STRATA, WHOLE, arm_able, default_choice, length, not_arm_able
from robot.truth import CENTRE_TOLERANCE, check_parse
from robot.world import WORKSPACE_SIDE
from vccjax.machine.program import parse
from vccjax.machine.scene import Scene, SceneObject

TRUTH = Scene((SceneObject("square", "red", 0.2, 0.3, 0.1), SceneObject("circle", "blue", 0.7, 0.6, 0.12),
               SceneObject("diamond", "green", 0.5, 0.85, 0.14)), (0.4, 0.5))


def _moved(scene: Scene, k: int, **change) -> Scene:
    objs = list(scene.objects)
    objs[k] = dataclasses.replace(objs[k], **change)
    return dataclasses.replace(scene, objects=tuple(objs))


def test_the_truth_itself_is_an_exact_parse_in_any_order():
    shuffled = dataclasses.replace(TRUTH, objects=TRUTH.objects[::-1])
    c = check_parse(TRUTH, shuffled)
    assert c.exact and c.problem() is None and c.match == (2, 1, 0)
    assert (c.objects, c.seen, c.found, c.exact_objects) == (3, 3, 3, 3)
    assert json.loads(json.dumps(c.record())) == c.record()  # what a scenario record keeps, as JSON


def test_each_way_a_parse_can_be_wrong_is_named():
    cases = [
        (dataclasses.replace(TRUTH, objects=TRUTH.objects[:2]), "1 of 3 objects not seen"),
        (dataclasses.replace(TRUTH, objects=(*TRUTH.objects, SceneObject("square", "red", 0.9, 0.1, 0.1))),
         "1 object(s) seen that are not there"),
        (_moved(TRUTH, 1, shape="square"), "1 shape(s) read wrong"),
        (_moved(TRUTH, 0, color="yellow"), "1 colour(s) read wrong"),
        (dataclasses.replace(TRUTH, pointer=None), "the pointer read wrong"),
        (dataclasses.replace(TRUTH, pointer=(0.4, 0.5 + 2 * CENTRE_TOLERANCE)), "the pointer read wrong"),
    ]
    for parsed, problem in cases:
        c = check_parse(TRUTH, parsed)
        assert not c.exact and c.problem() == problem, (problem, c)


def test_a_centre_off_by_more_than_the_tolerance_is_wrong_and_within_it_is_not():
    near = _moved(TRUTH, 2, x=0.5 + 0.9 * CENTRE_TOLERANCE)
    far = _moved(TRUTH, 2, x=0.5 + 1.5 * CENTRE_TOLERANCE)
    assert check_parse(TRUTH, near).exact
    c = check_parse(TRUTH, far)
    assert not c.exact and c.problem().startswith("a centre")
    assert c.centre_error_m == pytest.approx(1.5 * CENTRE_TOLERANCE * WORKSPACE_SIDE)
    assert c.exact_objects == 2 and c.found == 3  # still matched (within reach), not exact


def test_two_parsed_objects_never_claim_one_true_object():
    """Two objects seen where one stands: the nearer is it, the other is a phantom."""
    o = TRUTH.objects[0]
    twice = dataclasses.replace(TRUTH, objects=(*TRUTH.objects, dataclasses.replace(o, x=o.x + 0.01)))
    c = check_parse(TRUTH, twice)
    assert c.found == 3 and c.seen == 4 and sorted(j for j in c.match if j >= 0) == [0, 1, 2]
    assert c.match[3] == -1 and "not there" in c.problem()


GRAB = "scene_parse; fixate(left); top_down_attend; move_hand_to_attended_object; grab_object; move_hand_up"


def test_what_an_arm_cannot_do_is_named(monkeypatch):
    assert not_arm_able(parse(GRAB)) is None
    assert not_arm_able(parse("scene_parse; top_down_attend; fill_color(red)")) == "recolours an object"
    assert not_arm_able(parse("scene_parse; top_down_attend; remove_from_imagine_buffer")) == "removes an object"
    assert not_arm_able(parse("scene_parse; fixate(left); top_down_attend")) == "grabs nothing"
    assert not_arm_able(parse("scene_parse; imagine_object(circle); " + GRAB[13:])) == "imagines objects"
    star = "scene_parse; set_shape_attn(star); top_down_attend; move_hand_to_attended_object; grab_object"
    assert not_arm_able(parse(star)) is None  # the star plate stands for it
    import robot.world

    monkeypatch.setattr(robot.world, "BODIES", tuple(b for b in robot.world.BODIES if b.kind != "star"))
    assert not_arm_able(parse(star)) == "attends to stars, and no body on the table is one"
    assert not_arm_able([parse(GRAB), parse("scene_parse; top_down_attend; fill_color(red)")]) is not None


def _fake_concepts(sizes: dict[int, int]) -> dict:
    """`sizes[n]` grabbing programs of n instructions each (padded with fixations)."""
    out = {}
    for n, count in sizes.items():
        for k in range(count):
            out[f"c{n}_{k:03d}"] = parse(GRAB + "; fixate(left)" * (n - 6))
    out["paint"] = parse("scene_parse; top_down_attend; fill_color(red)")  # never chosen
    return out


def test_the_default_choice_takes_small_strata_whole_and_shares_the_rest_by_size():
    sizes = {6: 60, 10: 30, 14: 200, 16: 5}  # strata of 1-8, 9-12, 14 and 16+
    programs = _fake_concepts(sizes)
    chosen = default_choice(programs, 150, seed=0)
    assert len(chosen) == 150 == len(set(chosen)) and "paint" not in chosen and set(chosen) <= set(arm_able(programs))
    by = {n: sum(c.startswith(f"c{n}_") for c in chosen) for n in sizes}
    assert by[10] == 30 and by[16] == 5  # at most WHOLE: whole
    assert 30 <= WHOLE < 60
    left = 150 - 35  # shared by 60 and 200 in proportion: 26.5 and 88.5, rounded to sum 115
    assert by[6] + by[14] == left and abs(by[6] - left * 60 / 260) <= 1 and abs(by[14] - left * 200 / 260) <= 1
    assert default_choice(programs, 150, seed=0) == chosen and default_choice(programs, 150, seed=1) != chosen
    small = default_choice(programs, 20)  # fewer than the small strata hold: every stratum shares it
    assert len(small) == 20 and {n for n in sizes if any(c.startswith(f"c{n}_") for c in small)} >= {6, 10, 14}
    assert all(any(lo <= length(programs[c]) <= hi for lo, hi in STRATA) for c in chosen)


def test_a_choice_larger_than_the_concepts_takes_them_all():
    programs = _fake_concepts({6: 50, 14: 60})
    assert default_choice(programs, 1000) == sorted(arm_able(programs))
    assert np.all([c in programs for c in default_choice(programs, 10)])
