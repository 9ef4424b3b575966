"""Instructions of docs/vcc.md section 3, the imagination blackboard.

Each test runs its program on both machines (`run_both`), so it also checks that they
agree on the whole state; assertions are made on the reference machine `m`.
"""

from __future__ import annotations

import pytest

from tests.machine.instruction_helpers import (
    alive_ids,
    C,
    CENTRED,
    color_id,
    colors,
    COLORS,
    IMAGINE_KINDS,
    imagined,
    obj,
    run_both,
    scene,
    slot,
    THREE,
)


# =========================================================================================
# blackboard: fill_color, remove_from_imagine_buffer, imagine_object, reset_imagination
# =========================================================================================
class TestFillColor:
    @pytest.mark.parametrize("color", COLORS)
    def test_colors_attended_object(self, color):
        m, _ = run_both(f"scene_parse; top_down_attend; fill_color({color})", THREE)
        assert not m.failed
        assert colors(m) == [color_id("red"), color_id(color), color_id("blue")]
        assert m.output_scene().objects[1].color == color

    def test_fails_without_attended_object(self):
        m, _ = run_both("scene_parse; fill_color(red)", THREE)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "no attended object"

    def test_fails_after_next_object(self):
        m, _ = run_both("scene_parse; top_down_attend; next_object; fill_color(red)", THREE)
        assert m.failed and m.control.fail_index == 3


class TestRemoveFromImagineBuffer:
    def test_removes_attended_object(self):
        m, _ = run_both("scene_parse; top_down_attend; remove_from_imagine_buffer", THREE)
        assert not m.failed
        assert alive_ids(m) == [0, 2] and not slot(m, 1).alive
        assert m.attention.attended < 0 and m.attention.stale
        out = m.output_scene().objects
        assert len(out) == 2 and all(o.shape != "circle" for o in out)

    def test_removing_held_object_empties_hand(self):
        m, _ = run_both("scene_parse; top_down_attend; remove_from_imagine_buffer", CENTRED)
        assert not m.failed
        m, _ = run_both("scene_parse; grab_object; top_down_attend; remove_from_imagine_buffer", CENTRED)
        assert not m.failed and m.hand.held < 0 and m.output_scene().objects == ()
        m, _ = run_both("scene_parse; grab_object; top_down_attend; remove_from_imagine_buffer; "
                        "release_object", CENTRED)
        assert m.failed and m.control.fail_index == 4

    def test_removing_another_object_keeps_hold(self):
        sc = scene(obj("square", "red", 0.5, 0.5), obj("circle", "blue", 0.7, 0.5))
        m, _ = run_both("scene_parse; grab_object; next_object; top_down_attend; remove_from_imagine_buffer",
                        sc)
        assert not m.failed and m.hand.held == 0 and alive_ids(m) == [0]

    def test_fails_without_attended_object(self):
        m, _ = run_both("scene_parse; remove_from_imagine_buffer", THREE)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "no attended object"

    def test_fails_twice_in_a_row(self):
        m, _ = run_both("scene_parse; top_down_attend; remove_from_imagine_buffer; remove_from_imagine_buffer",
                        THREE)
        assert m.failed and m.control.fail_index == 3


class TestImagineObject:
    def test_imagines_circle_at_fovea(self):
        sc = scene(obj("square", "red", 0.1, 0.1), obj("circle", "blue", 0.9, 0.9))
        m, _ = run_both("scene_parse; imagine_object(circle)", sc)
        assert not m.failed and imagined(m) == (IMAGINE_KINDS.index("circle"), C, C)
        assert len(m.output_scene().objects) == 2  # never in the output

    def test_imagines_hline_at_fovea(self):
        sc = scene(obj("square", "red", 0.1, 0.5), obj("circle", "blue", 0.9, 0.9))
        m, _ = run_both("scene_parse; fixate(top); imagine_object(hline)", sc)
        assert not m.failed and imagined(m) == (IMAGINE_KINDS.index("hline"), C, 0)

    def test_imagined_object_is_never_attended(self):
        sc = scene(obj("square", "red", 0.1, 0.1))
        m, _ = run_both("scene_parse; imagine_object(circle); next_object", sc)
        assert not m.failed and m.attention.attended_list == [0]
        m, _ = run_both("scene_parse; imagine_object(circle); top_down_attend", scene())
        assert m.failed and m.control.fail_index == 2

    def test_fails_when_circle_overlaps_object(self):
        sc = scene(obj("square", "red", 0.5, 0.7))
        m, _ = run_both("scene_parse; imagine_object(circle)", sc)
        assert m.failed and m.control.fail_index == 1 and "overlap" in m.fail_reason

    def test_fails_when_hline_crosses_object(self):
        sc = scene(obj("square", "red", 0.05, 0.5, 0.06))
        m, _ = run_both("scene_parse; imagine_object(hline)", sc)
        assert m.failed and m.control.fail_index == 1 and "overlap" in m.fail_reason
        m, _ = run_both("scene_parse; fixate(top); imagine_object(hline)", sc)
        assert not m.failed  # the same object, the bar moved away

    def test_fails_when_one_exists(self):
        sc = scene(obj("square", "red", 0.1, 0.1))
        m, _ = run_both("scene_parse; imagine_object(circle); fixate(bottom); imagine_object(hline)", sc)
        assert m.failed and m.control.fail_index == 3 and "exists" in m.fail_reason


class TestResetImagination:
    def test_deletes_imagined_object(self):
        sc = scene(obj("square", "red", 0.1, 0.1))
        m, _ = run_both("scene_parse; imagine_object(circle); reset_imagination", sc)
        assert not m.failed and m.blackboard.imagined_kind < 0

    def test_allows_imagining_again(self):
        sc = scene(obj("square", "red", 0.1, 0.1))
        m, _ = run_both("scene_parse; imagine_object(circle); reset_imagination; imagine_object(hline)", sc)
        assert not m.failed and imagined(m) == (IMAGINE_KINDS.index("hline"), C, C)

    def test_fails_when_none_exists(self):
        m, _ = run_both("scene_parse; reset_imagination", THREE)
        assert m.failed and m.control.fail_index == 1 and "no imagined" in m.fail_reason
        sc = scene(obj("square", "red", 0.1, 0.1))
        m, _ = run_both("scene_parse; imagine_object(circle); reset_imagination; reset_imagination", sc)
        assert m.failed and m.control.fail_index == 3
