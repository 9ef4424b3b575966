"""Rivals of a reference program, and training pairs that rule them out."""

from __future__ import annotations

import numpy as np

from vccjax.world.pairs import TRAIN, Jitter, discriminate, distinguishes, make_pairs
from vccjax.machine.program import check_loop_syntax, parse
from vccjax.machine.reference import RefMachine
from vccjax.world.rivals import rival_programs
from vccjax.machine.scene import scenes_match

TWO_PARTS = parse(
    "scene_parse; set_color_attn(red); top_down_attend; move_hand_to_attended_object; grab_object; "
    "move_hand_left; release_object; reset_attn; set_shape_attn(circle); top_down_attend; "
    "move_hand_to_attended_object; grab_object; move_hand_right; release_object")
LOOP = parse(
    "scene_parse; fixate(right); set_color_attn(blue); loop_start; top_down_attend; move_hand_to_attended_object; "
    "grab_object; move_hand_right; release_object; next_object; loop_end")


def _texts(program):
    return {label: rival.text() for label, rival in rival_programs(program)}


def test_two_part_program_has_its_parts_swapped_and_each_deletion():
    texts = _texts(TWO_PARTS)
    swapped = texts["parts in order (1, 0)"]
    assert swapped.startswith("scene_parse; set_shape_attn(circle)")
    assert swapped.endswith("reset_attn; set_color_attn(red); top_down_attend; move_hand_to_attended_object; "
                            "grab_object; move_hand_left; release_object")
    assert "without set_color_attn at 1" in texts
    assert not any(label.startswith("without scene_parse") for label in texts)
    assert "without release_object at 13" not in texts  # a last release changes no output scene
    assert len(set(texts.values())) == len(texts) and TWO_PARTS.text() not in texts.values()


def test_loop_program_has_straight_passes_and_only_valid_deletions():
    texts = _texts(LOOP)
    body = "top_down_attend; move_hand_to_attended_object; grab_object; move_hand_right; release_object; next_object"
    assert texts["loop as 1 straight pass"] == f"scene_parse; fixate(right); set_color_attn(blue); {body}"
    assert texts["loop as 2 straight passes"].endswith(f"{body}; {body}")
    assert "without next_object at 9" not in texts  # a loop body must keep next_object
    assert "without fixate at 1" in texts
    for _, rival in rival_programs(LOOP):
        check_loop_syntax(rival)


def test_each_of_two_loops_is_unrolled_with_the_other_kept():
    first = "set_color_attn(yellow); loop_start; top_down_attend; move_hand_to_attended_object; grab_object; " \
            "move_hand_down; release_object; next_object; loop_end"
    second = "set_color_attn(green); loop_start; top_down_attend; move_hand_to_attended_object; grab_object; " \
             "move_hand_up; release_object; next_object; loop_end"
    texts = _texts(parse(f"scene_parse; {first}; reset_attn; {second}"))
    body1 = first.split("loop_start; ")[1].removesuffix("; loop_end")
    body2 = second.split("loop_start; ")[1].removesuffix("; loop_end")
    assert texts["loop 1 as 1 straight pass"] == f"scene_parse; set_color_attn(yellow); {body1}; reset_attn; {second}"
    assert texts["loop 2 as 2 straight passes"] == (
        f"scene_parse; {first}; reset_attn; set_color_attn(green); {body2}; {body2}")
    assert {"loop 1 as 2 straight passes", "loop 2 as 1 straight pass", "parts in order (1, 0)"} <= set(texts)


def test_discriminate_rules_out_every_rival_or_says_which_it_could_not():
    rng = np.random.default_rng(5)
    pairs = make_pairs(LOOP, TRAIN, rng)
    rivals = [r for _, r in rival_programs(LOOP)]
    slack = Jitter().slack
    before = [r for r in rivals if not any(distinguishes(r, a, b, margin=slack) for a, b in pairs)]
    new, left = discriminate(LOOP, pairs, rivals, TRAIN, rng)
    assert before, "the random pairs alone should leave some rival untold, or this test shows nothing"
    assert len(new) == TRAIN.count
    for r, rival in enumerate(rivals):
        assert any(distinguishes(rival, a, b, margin=slack) for a, b in new) == (r not in left)
    for a, b in new:  # swapped-in pairs are still what the program does
        m = RefMachine(a, validate=False).run(LOOP)
        assert not m.failed and scenes_match(m.output_scene(), b, 1e-9)


def test_discriminate_is_deterministic():
    def run():
        rng = np.random.default_rng(9)
        pairs = make_pairs(TWO_PARTS, TRAIN, rng)
        new, left = discriminate(TWO_PARTS, pairs, [r for _, r in rival_programs(TWO_PARTS)], TRAIN, rng)
        return [(a.objects, b.objects) for a, b in new], left

    assert run() == run()
