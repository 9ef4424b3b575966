"""Instructions of docs/vcc.md section 3, loops: bodies, replays, zero iterations, failure indices.

Each test runs its program on both machines (`run_both`), so it also checks that they
agree on the whole state; assertions are made on the reference machine `m`.
"""

from __future__ import annotations

import pytest

from tests.machine.instruction_helpers import (
    alive_ids,
    CENTRE,
    centre_of,
    CFG,
    color_id,
    colors,
    obj,
    run_both,
    scene,
    slot,
)


# =========================================================================================
# loops: loop_start, loop_end
# =========================================================================================
LOOP_SCENE = scene(
    obj("square", "red", 0.2, 0.2),  # 0: far
    obj("circle", "green", 0.65, 0.5),  # 1: nearest
    obj("diamond", "blue", 0.5, 0.8),  # 2: middle
)
ORIGINAL_COLORS = [color_id("red"), color_id("green"), color_id("blue")]


class TestLoops:
    def test_loop_start_refreshes_attended_list(self):
        m, _ = run_both("scene_parse; fixate(left); loop_start", LOOP_SCENE)
        assert not m.failed and not m.attention.stale and m.attention.attended_list == [0, 2, 1]
        assert m.attention.cursor == 0 and m.control.in_loop

    def test_loop_start_keeps_a_fresh_list(self):
        m, _ = run_both("scene_parse; top_down_attend; fixate(left); loop_start", LOOP_SCENE)
        assert m.attention.attended_list == [1, 2, 0]

    def test_first_iteration_runs_eagerly(self):
        m, _ = run_both("scene_parse; loop_start; top_down_attend; fill_color(yellow)", LOOP_SCENE)
        assert not m.failed and m.attention.attended == 1
        assert colors(m) == [color_id("red"), color_id("yellow"), color_id("blue")]

    def test_loop_end_replays_over_all_attended_objects(self):
        m, _ = run_both("scene_parse; loop_start; top_down_attend; fill_color(yellow); next_object; loop_end",
                        LOOP_SCENE)
        assert not m.failed and not m.control.in_loop
        assert colors(m) == [color_id("yellow")] * 3
        assert m.attention.cursor == 3 and m.attention.attended < 0

    def test_replay_visits_objects_in_attention_order(self):
        m, _ = run_both("scene_parse; loop_start; top_down_attend; fixate_attended_object; next_object; "
                        "loop_end", LOOP_SCENE)
        assert not m.failed
        assert m.fovea.history == [CENTRE] + [centre_of(m, i) for i in (1, 2, 0)]

    def test_loop_over_filtered_objects(self):
        sc = scene(obj("square", "red", 0.2, 0.2), obj("circle", "blue", 0.6, 0.5),
                   obj("triangle", "red", 0.8, 0.8))
        m, _ = run_both("scene_parse; set_color_attn(red); loop_start; top_down_attend; fill_color(green); "
                        "next_object; loop_end", sc)
        assert not m.failed and m.attention.cursor == 2
        assert colors(m) == [color_id("green"), color_id("blue"), color_id("green")]

    def test_loop_starting_mid_list(self):
        m, _ = run_both("scene_parse; next_object; loop_start; top_down_attend; fill_color(yellow); "
                        "next_object; loop_end", LOOP_SCENE)
        assert not m.failed and m.attention.cursor == 3
        assert colors(m) == [color_id("yellow"), color_id("green"), color_id("yellow")]

    def test_iterations_bounded_by_n_max(self):
        # n_max objects: the loop runs exactly n_max iterations (the most it may run)
        objs = [obj("circle", "red", 0.1 + 0.2 * (i % 5), 0.3 + 0.4 * (i // 5), 0.08)
                for i in range(CFG.n_max)]
        m, _ = run_both("scene_parse; loop_start; top_down_attend; fill_color(blue); next_object; loop_end",
                        scene(*objs))
        assert not m.failed and m.attention.cursor == CFG.n_max
        assert all(c == color_id("blue") for c in colors(m))

    def test_body_advancing_twice_stops_when_cursor_reaches_end(self):
        sc = scene(*LOOP_SCENE.objects, obj("star", "yellow", 0.85, 0.15))
        m, _ = run_both("scene_parse; loop_start; top_down_attend; fill_color(red); next_object; next_object; "
                        "loop_end", sc)
        # A = [1, 2, 0, 3]: the body attends A[0] = 1 and A[2] = 0 only
        assert not m.failed and m.attention.cursor == 4 and m.attention.attended_list == [1, 2, 0, 3]
        assert colors(m) == [color_id("red"), color_id("red"), color_id("blue"),
                                                color_id("yellow")]

    def test_body_advancing_twice_fails_past_end_in_replay(self):
        m, _ = run_both("scene_parse; loop_start; top_down_attend; next_object; next_object; loop_end",
                        LOOP_SCENE)
        assert m.failed and m.control.fail_index == 4  # the second next_object, during the replay

    def test_failure_in_replay_reports_body_index(self):
        m, _ = run_both("scene_parse; loop_start; top_down_attend; move_hand_to_attended_object; grab_object; "
                        "next_object; loop_end", LOOP_SCENE)
        assert m.failed and m.control.fail_index == 4 and "already holding" in m.fail_reason

    def test_failure_in_eager_iteration_reports_its_index(self):
        m, _ = run_both("scene_parse; loop_start; top_down_attend; release_object; next_object; loop_end",
                        LOOP_SCENE)
        assert m.failed and m.control.fail_index == 3

    def test_removal_in_body_shrinks_list(self):
        # next_object refreshes the list after each removal, so the cursor runs past its end
        m, _ = run_both("scene_parse; loop_start; top_down_attend; remove_from_imagine_buffer; next_object; "
                        "loop_end", LOOP_SCENE)
        assert m.failed and m.control.fail_index == 4
        assert alive_ids(m) == [2]  # removed 1 (eager), then 0 (farthest of the rest)

    @pytest.mark.parametrize("prefix", ["set_shape_attn(star)", "next_object; next_object; next_object"])
    def test_zero_iterations_record_but_do_not_run(self, prefix):
        n = len(prefix.split(";"))
        m, _ = run_both(f"scene_parse; {prefix}; loop_start; top_down_attend; release_object; fill_color(red); "
                        "fixate(left); next_object; loop_end", LOOP_SCENE)
        assert not m.failed and not m.control.in_loop
        assert colors(m) == ORIGINAL_COLORS
        assert m.fovea.history == [CENTRE] and m.attention.cursor == (0 if n == 1 else 3)
        assert m.attention.attended < 0

    def test_zero_iteration_loop_still_rejects_forbidden_instruction(self):
        m, _ = run_both("scene_parse; set_shape_attn(star); loop_start; top_down_attend; reset_attn; "
                        "next_object; loop_end", LOOP_SCENE)
        assert m.failed and m.control.fail_index == 4

    def test_zero_iteration_loop_still_needs_required_instructions(self):
        m, _ = run_both("scene_parse; set_shape_attn(star); loop_start; top_down_attend; loop_end", LOOP_SCENE)
        assert m.failed and m.control.fail_index == 4 and "lacks" in m.fail_reason

    @pytest.mark.parametrize("forbidden", ["set_shape_attn(circle)", "set_color_attn(red)", "reset_attn",
                                           "loop_start"])
    def test_forbidden_instruction_in_body_fails_where_it_stands(self, forbidden):
        m, _ = run_both(f"scene_parse; loop_start; top_down_attend; fill_color(yellow); {forbidden}; "
                        "next_object; loop_end", LOOP_SCENE)
        assert m.failed and m.control.fail_index == 4 and "not allowed in a loop body" in m.fail_reason
        assert m.attention.shape_filter < 0 and m.attention.color_filter < 0

    @pytest.mark.parametrize("body, end", [("top_down_attend; fill_color(yellow)", 4),
                                           ("fixate(left); next_object", 4),
                                           ("fixate(left)", 3)])
    def test_body_lacking_required_instruction_fails_at_loop_end(self, body, end):
        m, _ = run_both(f"scene_parse; loop_start; {body}; loop_end", LOOP_SCENE)
        assert m.failed and m.control.fail_index == end and "lacks" in m.fail_reason

    def test_loop_end_without_loop_start_fails(self):
        m, _ = run_both("scene_parse; loop_end", LOOP_SCENE)
        assert m.failed and m.control.fail_index == 1 and "without loop_start" in m.fail_reason
        m, _ = run_both("scene_parse; loop_start; top_down_attend; next_object; loop_end; loop_end",
                        LOOP_SCENE)
        assert m.failed and m.control.fail_index == 5

    def test_two_loops_in_sequence(self):
        m, _ = run_both("scene_parse; set_shape_attn(circle); loop_start; top_down_attend; fill_color(red); "
                        "next_object; loop_end; reset_attn; loop_start; top_down_attend; fixate_attended_object; "
                        "next_object; loop_end", LOOP_SCENE)
        assert not m.failed and m.attention.cursor == 3 and len(m.fovea.history) == 4
        assert slot(m, 1).color == color_id("red")

    def test_body_of_body_max_instructions_runs(self):
        assert CFG.body_max == 24
        body = ["top_down_attend"] + ["fill_color(yellow)"] * (CFG.body_max - 2) + ["next_object"]
        m, _ = run_both("scene_parse; loop_start; " + "; ".join(body) + "; loop_end", LOOP_SCENE)
        assert not m.failed and m.attention.cursor == 3
        assert all(c == color_id("yellow") for c in colors(m))

    def test_body_longer_than_body_max_fails(self):
        body = ["top_down_attend"] + ["fill_color(yellow)"] * (CFG.body_max - 1) + ["next_object"]
        m, _ = run_both("scene_parse; loop_start; " + "; ".join(body) + "; loop_end", LOOP_SCENE)
        assert m.failed and m.control.fail_index == 2 + CFG.body_max and "body_max" in m.fail_reason
