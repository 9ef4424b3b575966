"""Instructions of docs/vcc.md section 3, attention: the filters, top-down attention, the attended list and the pointer.

Each test runs its program on both machines (`run_both`), so it also checks that they
agree on the whole state; assertions are made on the reference machine `m`.
"""

from __future__ import annotations

import pytest

from tests.machine.instruction_helpers import (
    color_id,
    FILTER_SCENE,
    obj,
    run_both,
    scene,
    shape_id,
    THREE,
)


# =========================================================================================
# attention: set_shape_attn, set_color_attn, reset_attn, top_down_attend, next_object
# =========================================================================================
class TestSetShapeAttn:
    def test_sets_filter_and_resets_attention(self):
        m, _ = run_both(
            "scene_parse; top_down_attend; next_object; top_down_attend; set_shape_attn(circle)",
            FILTER_SCENE,
        )
        assert not m.failed
        assert m.attention.shape_filter == shape_id("circle") and m.attention.color_filter < 0
        assert m.attention.stale and m.attention.cursor == 0 and m.attention.attended < 0

    def test_filters_attended_list_by_shape(self):
        m, _ = run_both("scene_parse; set_shape_attn(square); top_down_attend", FILTER_SCENE)
        assert m.attention.attended_list == [1, 0] and m.attention.attended == 1

    def test_fails_when_shape_filter_already_set(self):
        m, _ = run_both("scene_parse; set_shape_attn(circle); set_shape_attn(square)", FILTER_SCENE)
        assert m.failed and m.control.fail_index == 2 and "already set" in m.fail_reason

    def test_fails_when_set_again_to_the_same_shape(self):
        m, _ = run_both("scene_parse; set_shape_attn(circle); set_shape_attn(circle)", FILTER_SCENE)
        assert m.failed and m.control.fail_index == 2

    def test_color_filter_does_not_block_shape_filter(self):
        m, _ = run_both("scene_parse; set_color_attn(red); set_shape_attn(circle)", FILTER_SCENE)
        assert not m.failed
        assert (m.attention.shape_filter, m.attention.color_filter) == (shape_id("circle"), color_id("red"))

    def test_can_be_set_again_after_reset_attn(self):
        m, _ = run_both(
            "scene_parse; set_shape_attn(circle); reset_attn; set_shape_attn(square); top_down_attend",
            FILTER_SCENE,
        )
        assert not m.failed and m.attention.shape_filter == shape_id("square") and m.attention.attended_list == [1, 0]

    def test_no_match_gives_empty_list_and_top_down_attend_fails(self):
        m, _ = run_both("scene_parse; set_shape_attn(star); top_down_attend", FILTER_SCENE)
        assert m.failed and m.control.fail_index == 2
        m, _ = run_both("scene_parse; set_shape_attn(star); next_object", FILTER_SCENE)
        assert m.failed and m.control.fail_index == 2  # k = 1 > len(A) = 0

    def test_forbidden_in_loop_body(self):
        m, _ = run_both(
            "scene_parse; loop_start; top_down_attend; set_shape_attn(circle); next_object; loop_end",
            FILTER_SCENE,
        )
        assert m.failed and m.control.fail_index == 3 and "loop body" in m.fail_reason


class TestSetColorAttn:
    def test_sets_filter_and_resets_attention(self):
        m, _ = run_both(
            "scene_parse; top_down_attend; next_object; top_down_attend; set_color_attn(blue)",
            FILTER_SCENE,
        )
        assert not m.failed
        assert m.attention.color_filter == color_id("blue") and m.attention.shape_filter < 0
        assert m.attention.stale and m.attention.cursor == 0 and m.attention.attended < 0

    def test_filters_attended_list_by_color(self):
        m, _ = run_both("scene_parse; set_color_attn(red); top_down_attend", FILTER_SCENE)
        assert m.attention.attended_list == [2, 0] and m.attention.attended == 2

    @pytest.mark.parametrize(
        "shape, color, expected",
        [("square", "blue", [1]), ("circle", "red", [2]), ("circle", "blue", [3]),
         ("square", "red", [0]), ("star", "red", []), ("square", "yellow", [])],
    )
    def test_shape_and_color_filters_combine(self, shape, color, expected):
        m, _ = run_both(f"scene_parse; set_shape_attn({shape}); set_color_attn({color}); next_object",
                        FILTER_SCENE)
        if expected:
            assert not m.failed and m.attention.attended_list == expected
        else:  # next_object: k = 1 > len(A) = 0
            assert m.failed and m.control.fail_index == 3

    def test_color_filter_sees_filled_color(self):
        m, _ = run_both(
            "scene_parse; top_down_attend; fill_color(green); set_color_attn(green); top_down_attend",
            FILTER_SCENE,
        )
        assert not m.failed and m.attention.attended_list == [3] and m.attention.attended == 3

    def test_fails_when_color_filter_already_set(self):
        m, _ = run_both("scene_parse; set_color_attn(red); set_shape_attn(square); set_color_attn(blue)",
                        FILTER_SCENE)
        assert m.failed and m.control.fail_index == 3 and "already set" in m.fail_reason

    def test_forbidden_in_loop_body(self):
        m, _ = run_both(
            "scene_parse; loop_start; top_down_attend; next_object; set_color_attn(red); loop_end",
            FILTER_SCENE,
        )
        assert m.failed and m.control.fail_index == 4 and "loop body" in m.fail_reason


class TestResetAttn:
    def test_unsets_both_filters_and_resets_attention(self):
        m, _ = run_both(
            "scene_parse; set_shape_attn(circle); set_color_attn(blue); top_down_attend; next_object; "
            "reset_attn",
            FILTER_SCENE,
        )
        assert not m.failed
        assert m.attention.shape_filter < 0 and m.attention.color_filter < 0
        assert m.attention.stale and m.attention.cursor == 0 and m.attention.attended < 0

    def test_attends_everything_after_reset(self):
        m, _ = run_both("scene_parse; set_shape_attn(circle); top_down_attend; reset_attn; top_down_attend",
                        FILTER_SCENE)
        assert m.attention.attended_list == [3, 2, 1, 0] and m.attention.attended == 3

    def test_never_fails_without_filters(self):
        m, _ = run_both("scene_parse; reset_attn; reset_attn", FILTER_SCENE)
        assert not m.failed and m.attention.stale

    def test_forbidden_in_loop_body(self):
        m, _ = run_both("scene_parse; loop_start; top_down_attend; reset_attn; next_object; loop_end",
                        FILTER_SCENE)
        assert m.failed and m.control.fail_index == 3 and "loop body" in m.fail_reason


class TestTopDownAttend:
    def test_orders_by_distance_from_fovea(self):
        m, _ = run_both("scene_parse; top_down_attend", THREE)
        assert not m.failed
        assert m.attention.attended_list == [1, 2, 0] and not m.attention.stale
        assert m.attention.attended == 1 and m.attention.cursor == 0

    def test_ties_broken_by_slot(self):
        sc = scene(
            obj("circle", "red", 0.7, 0.5),  # 0: distance .2
            obj("circle", "red", 0.3, 0.5),  # 1: distance .2
            obj("circle", "red", 0.5, 0.7),  # 2: distance .2
            obj("circle", "red", 0.5, 0.6, 0.06),  # 3: nearest
            obj("circle", "red", 0.5, 0.3),  # 4: distance .2
        )
        m, _ = run_both("scene_parse; top_down_attend", sc)
        assert m.attention.attended_list == [3, 0, 1, 2, 4]

    def test_orders_from_fovea_at_refresh_time(self):
        m, _ = run_both("scene_parse; fixate(left); top_down_attend", THREE)
        assert m.attention.attended_list == [0, 2, 1] and m.attention.attended == 0
        m, _ = run_both("scene_parse; fixate(right); top_down_attend", THREE)
        assert m.attention.attended_list == [1, 2, 0]
        m, _ = run_both("scene_parse; fixate(bottom); top_down_attend", THREE)
        assert m.attention.attended_list == [2, 1, 0]

    def test_refreshes_only_when_stale(self):
        m, _ = run_both("scene_parse; top_down_attend; fixate(left); top_down_attend", THREE)
        assert m.attention.attended_list == [1, 2, 0] and m.attention.attended == 1  # not re-sorted from the left
        m, _ = run_both("scene_parse; top_down_attend; fixate(left); reset_attn; top_down_attend", THREE)
        assert m.attention.attended_list == [0, 2, 1] and m.attention.attended == 0

    def test_uses_current_object_positions(self):
        sc = scene(obj("square", "red", 0.5, 0.5), obj("circle", "blue", 0.7, 0.5))
        m, _ = run_both("scene_parse; grab_object; move_hand_left; top_down_attend", sc)
        assert not m.failed and m.attention.attended_list == [1, 0]
        m, _ = run_both("scene_parse; top_down_attend", sc)
        assert m.attention.attended_list == [0, 1]

    def test_attends_at_cursor(self):
        m, _ = run_both("scene_parse; next_object; top_down_attend", THREE)
        assert m.attention.cursor == 1 and m.attention.attended == 2
        m, _ = run_both("scene_parse; next_object; next_object; top_down_attend", THREE)
        assert m.attention.cursor == 2 and m.attention.attended == 0

    def test_fails_when_cursor_reaches_end(self):
        m, _ = run_both("scene_parse; next_object; next_object; next_object; top_down_attend", THREE)
        assert m.failed and m.control.fail_index == 4 and "cursor" in m.fail_reason

    def test_fails_on_empty_scene(self):
        m, _ = run_both("scene_parse; top_down_attend", scene())
        assert m.failed and m.control.fail_index == 1

    def test_skips_removed_objects(self):
        m, _ = run_both("scene_parse; top_down_attend; remove_from_imagine_buffer; top_down_attend", THREE)
        assert not m.failed and m.attention.attended_list == [2, 0] and m.attention.attended == 2


class TestNextObject:
    def test_advances_cursor_and_clears_attended(self):
        m, _ = run_both("scene_parse; top_down_attend; next_object", THREE)
        assert not m.failed and m.attention.cursor == 1 and m.attention.attended < 0

    def test_refreshes_a_stale_list(self):
        m, _ = run_both("scene_parse; fixate(left); next_object", THREE)
        assert not m.attention.stale and m.attention.attended_list == [0, 2, 1] and m.attention.cursor == 1

    def test_cursor_may_equal_list_length(self):
        m, _ = run_both("scene_parse; next_object; next_object; next_object", THREE)
        assert not m.failed and m.attention.cursor == 3 == len(m.attention.attended_list)

    def test_fails_past_the_end(self):
        m, _ = run_both("scene_parse; next_object; next_object; next_object; next_object", THREE)
        assert m.failed and m.control.fail_index == 4 and "beyond" in m.fail_reason

    def test_fails_on_empty_list(self):
        m, _ = run_both("scene_parse; next_object", scene())
        assert m.failed and m.control.fail_index == 1


class TestAttendPointer:
    SC = scene(obj("square", "red", 0.2, 0.2), obj("circle", "blue", 0.7, 0.6), pointer=(0.72, 0.58))

    def test_attends_object_under_pointer(self):
        m, _ = run_both("scene_parse; attend_pointer", self.SC)
        assert not m.failed and m.attention.attended == 1
        assert m.attention.stale and m.attention.cursor == 0  # A and k untouched

    def test_does_not_touch_list_or_cursor(self):
        m, _ = run_both("scene_parse; top_down_attend; next_object; attend_pointer", self.SC)
        assert not m.failed and m.attention.attended == 1
        assert m.attention.cursor == 1 and m.attention.attended_list == [1, 0] and not m.attention.stale

    def test_fails_without_pointer(self):
        sc = scene(obj("circle", "blue", 0.5, 0.5))
        m, _ = run_both("scene_parse; attend_pointer", sc)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "no pointer"

    def test_fails_when_nothing_under_pointer(self):
        sc = scene(obj("circle", "blue", 0.7, 0.6), pointer=(0.3, 0.3))
        m, _ = run_both("scene_parse; attend_pointer", sc)
        assert m.failed and m.control.fail_index == 1 and "under the pointer" in m.fail_reason

    def test_fails_when_object_under_pointer_was_removed(self):
        m, _ = run_both("scene_parse; attend_pointer; remove_from_imagine_buffer; attend_pointer", self.SC)
        assert m.failed and m.control.fail_index == 3


