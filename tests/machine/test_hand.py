"""Instructions of docs/vcc.md section 3, the hand: moves, grabbing and releasing.

Each test runs its program on both machines (`run_both`), so it also checks that they
agree on the whole state; assertions are made on the reference machine `m`.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.machine.instruction_helpers import (
    assert_in_contact,
    assert_no_overlap,
    box_gap,
    C,
    centre_of,
    CENTRED,
    CFG,
    IMAGINE_KINDS,
    imagined,
    imagined_pixels,
    mask,
    mask_extent,
    obj,
    PIXEL,
    run_both,
    scene,
    slot,
    SUB,
    THREE,
    U,
    u,
)


# =========================================================================================
# hand: move_hand_to_attended_object, grab_object, release_object
# =========================================================================================
class TestMoveHandToAttendedObject:
    def test_moves_empty_hand_to_attended_centre(self):
        sc = scene(obj("triangle", "red", 0.3, 0.7), obj("circle", "blue", 0.9, 0.9))
        m, _ = run_both("scene_parse; top_down_attend; move_hand_to_attended_object", sc)
        assert not m.failed and m.hand.position == (u(0.3), u(0.7)) and m.hand.held < 0
        assert centre_of(m, 0) == (u(0.3), u(0.7))  # nothing moved

    def test_fails_without_attended_object(self):
        m, _ = run_both("scene_parse; move_hand_to_attended_object", THREE)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "no attended object"

    def test_fails_when_attended_is_held(self):
        m, _ = run_both("scene_parse; top_down_attend; move_hand_to_attended_object; grab_object; "
                        "move_hand_to_attended_object", THREE)
        assert m.failed and m.control.fail_index == 4 and "held" in m.fail_reason

    def test_carries_held_object_until_contact_horizontally(self):
        sc = scene(obj("square", "red", 0.25, 0.5), obj("circle", "blue", 0.8, 0.5))
        m, _ = run_both("scene_parse; top_down_attend; move_hand_to_attended_object; grab_object; "
                        "next_object; top_down_attend; move_hand_to_attended_object", sc)
        assert not m.failed and m.hand.held == 0 and m.attention.attended == 1
        x, y = centre_of(m, 0)
        assert y == u(0.5) and u(0.25) < x < u(0.8)
        assert centre_of(m, 1) == (u(0.8), u(0.5))  # the target does not move
        assert m.hand.position == (x, y)  # the hand keeps its place on the object
        assert_no_overlap(m)
        assert_in_contact(m, 0, [(1, 0)])
        # adjacent: the masks are at most a pixel apart, about a width apart in centres
        assert abs((u(0.8) - x) - 0.5 * (0.1 + 0.1) * U) <= 2 * SUB

    def test_carries_held_object_until_contact_diagonally(self):
        sc = scene(obj("diamond", "green", 0.25, 0.25), obj("square", "yellow", 0.75, 0.75))
        before = np.hypot(0.5, 0.5) * U
        m, _ = run_both("scene_parse; top_down_attend; move_hand_to_attended_object; grab_object; "
                        "next_object; top_down_attend; move_hand_to_attended_object", sc)
        assert not m.failed
        (x0, y0), (x1, y1) = centre_of(m, 0), centre_of(m, 1)
        assert (x1, y1) == (u(0.75), u(0.75))
        assert np.hypot(x1 - x0, y1 - y0) < before / 3
        assert x0 - u(0.25) == y0 - u(0.25)  # straight along the diagonal
        assert m.hand.position == (x0, y0)
        assert_no_overlap(m)
        assert_in_contact(m, 0, [(1, 0), (0, 1), (1, 1)])


class TestGrabObject:
    def test_grabs_object_under_hand(self):
        sc = scene(obj("circle", "blue", 0.2, 0.8), obj("square", "red", 0.52, 0.48))
        m, _ = run_both("scene_parse; grab_object", sc)
        assert not m.failed and m.hand.held == 1
        assert m.attention.attended < 0  # grabbing does not attend

    def test_grabs_attended_object_after_moving_hand(self):
        sc = scene(obj("star", "yellow", 0.31, 0.67, 0.05), obj("circle", "blue", 0.8, 0.2))
        m, _ = run_both("scene_parse; top_down_attend; move_hand_to_attended_object; grab_object", sc)
        assert not m.failed and m.attention.attended == 0 and m.hand.held == 0  # the centre pixel is in the mask

    def test_fails_when_nothing_under_hand(self):
        m, _ = run_both("scene_parse; grab_object", THREE)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "no object at the hand"

    def test_fails_when_already_holding(self):
        m, _ = run_both("scene_parse; grab_object; grab_object", CENTRED)
        assert m.failed and m.control.fail_index == 2 and "already holding" in m.fail_reason

    def test_fails_on_removed_object(self):
        m, _ = run_both("scene_parse; top_down_attend; remove_from_imagine_buffer; grab_object", CENTRED)
        assert m.failed and m.control.fail_index == 3

    def test_never_grabs_imagined_object(self):
        # the hand is at the centre, inside the imagined circle; no real object there
        sc = scene(obj("square", "red", 0.1, 0.1))
        m, _ = run_both("scene_parse; imagine_object(circle); grab_object", sc)
        assert m.failed and m.control.fail_index == 2


class TestReleaseObject:
    def test_releases_in_place(self):
        m, _ = run_both("scene_parse; grab_object; move_hand_right; release_object", CENTRED)
        assert not m.failed and m.hand.held < 0
        assert m.hand.position == centre_of(m, 0) and slot(m, 0).x > C

    def test_fails_when_not_holding(self):
        m, _ = run_both("scene_parse; release_object", CENTRED)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "not holding an object"

    def test_released_object_is_no_longer_carried(self):
        m, _ = run_both("scene_parse; grab_object; release_object; move_hand_left", CENTRED)
        assert m.failed and m.control.fail_index == 3

    def test_can_grab_again_after_release(self):
        m, _ = run_both("scene_parse; grab_object; release_object; grab_object", CENTRED)
        assert not m.failed and m.hand.held == 0


# =========================================================================================
# directional moves: move_hand_left / right / up / down
# =========================================================================================
DIRECTIONS = {  # name: (pixel step, blocker position in that direction)
    "left": ((-1, 0), (0.2, 0.5)),
    "right": ((1, 0), (0.8, 0.5)),
    "up": ((0, -1), (0.5, 0.2)),
    "down": ((0, 1), (0.5, 0.8)),
}


class TestMoveHandDirection:
    @pytest.mark.parametrize("direction", list(DIRECTIONS))
    @pytest.mark.parametrize("shape", ["square", "circle", "triangle", "star"])
    def test_stops_at_workspace_edge(self, direction, shape):
        w = 0.1
        sc = scene(obj(shape, "red", 0.5, 0.5, w))
        m, _ = run_both(f"scene_parse; grab_object; move_hand_{direction}", sc)
        assert not m.failed and m.hand.held == 0
        o = slot(m, 0)
        x, y = o.x / U, o.y / U
        # the w x w box stays in the workspace, and one more pixel would take it out
        edge = {"left": x - w / 2, "right": 1 - (x + w / 2), "up": y - w / 2, "down": 1 - (y + w / 2)}
        assert 0 <= edge[direction] < PIXEL
        assert (x, y)[direction in ("left", "right")] == 0.5  # it moved along one axis only
        m.output_scene().validate()
        assert m.hand.position == (o.x, o.y)  # the hand moved with the object
        # the displacement is whole pixels
        assert (o.x - C) % SUB == 0 and (o.y - C) % SUB == 0

    @pytest.mark.parametrize("direction", list(DIRECTIONS))
    def test_fails_when_not_holding(self, direction):
        m, _ = run_both(f"scene_parse; move_hand_{direction}", CENTRED)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "not holding an object"

    @pytest.mark.parametrize("direction", list(DIRECTIONS))
    def test_stops_at_contact_with_object(self, direction):
        step, (bx, by) = DIRECTIONS[direction]
        sc = scene(obj("square", "red", 0.5, 0.5), obj("circle", "blue", bx, by))
        m, _ = run_both(f"scene_parse; grab_object; move_hand_{direction}", sc)
        assert not m.failed
        x, y = centre_of(m, 0)
        assert (x - C) * step[0] > 0 or (y - C) * step[1] > 0  # it moved toward the blocker
        assert (x - C) * step[1] == 0 and (y - C) * step[0] == 0  # only along the direction
        assert centre_of(m, 1) == (u(bx), u(by))
        assert m.hand.position == (x, y)
        assert_no_overlap(m)
        assert_in_contact(m, 0, [step])

    def test_ignores_objects_off_the_path(self):
        sc = scene(obj("square", "red", 0.5, 0.5), obj("circle", "blue", 0.15, 0.25))
        m, _ = run_both("scene_parse; grab_object; move_hand_left", sc)
        assert box_gap(m, 0, "left") < PIXEL  # reached the left edge

    def test_removed_object_does_not_block(self):
        sc = scene(obj("square", "red", 0.5, 0.5), obj("circle", "blue", 0.2, 0.5))
        m, _ = run_both("scene_parse; grab_object; set_shape_attn(circle); top_down_attend; "
                        "remove_from_imagine_buffer; move_hand_left", sc)
        assert not m.failed and box_gap(m, 0, "left") < PIXEL

    @pytest.mark.parametrize("direction, start", [("down", 0.25), ("up", 0.75)])
    def test_stops_at_imagined_hline(self, direction, start):
        sc = scene(obj("square", "red", 0.5, start))
        m, _ = run_both("scene_parse; imagine_object(hline); top_down_attend; move_hand_to_attended_object; "
                        f"grab_object; move_hand_{direction}", sc)
        assert not m.failed and imagined(m) == (IMAGINE_KINDS.index("hline"), C, C)
        x, y = centre_of(m, 0)
        assert x == C and (y > u(start) if direction == "down" else y < u(start))
        rows = set(imagined_pixels(1, C, C, CFG)[0].tolist())
        rmin, rmax, _, _ = mask_extent(m, 0)
        if direction == "down":
            assert rmax == min(rows) - 1
        else:
            assert rmin == max(rows) + 1
        assert_in_contact(m, 0, [DIRECTIONS[direction][0]])

    def test_hline_does_not_block_horizontal_moves(self):
        sc = scene(obj("square", "red", 0.5, 0.25))
        m, _ = run_both("scene_parse; imagine_object(hline); top_down_attend; move_hand_to_attended_object; "
                        "grab_object; move_hand_right", sc)
        assert not m.failed and box_gap(m, 0, "right") < PIXEL

    def test_stops_at_imagined_circle_then_free_after_reset(self):
        sc = scene(obj("square", "red", 0.85, 0.5))
        prog = ("scene_parse; imagine_object(circle); top_down_attend; move_hand_to_attended_object; "
                "grab_object; move_hand_left")
        m, _ = run_both(prog, sc)
        assert not m.failed
        x, y = centre_of(m, 0)
        assert y == C and x < u(0.85)
        assert abs((x / U - 0.05) - 0.75) <= 2 * PIXEL  # left edge at the circle's rim
        assert_in_contact(m, 0, [(-1, 0)])
        m, _ = run_both(prog + "; reset_imagination; move_hand_left", sc)
        assert not m.failed and m.blackboard.imagined_kind < 0 and box_gap(m, 0, "left") < PIXEL


# =========================================================================================
# move_hand_to_pointer, move_hand_to_fixate_collision
# =========================================================================================
class TestMoveHandToPointer:
    @pytest.mark.parametrize("pointer", [(0.3, 0.7), (0.27, 0.71), (0.8, 0.15), (0.5, 0.9)])
    def test_arrives_at_pointer(self, pointer):
        sc = scene(obj("square", "red", 0.5, 0.5), pointer=pointer)
        m, _ = run_both("scene_parse; grab_object; move_hand_to_pointer", sc)
        assert not m.failed
        o = slot(m, 0)
        assert abs(o.x / U - pointer[0]) <= PIXEL / 2 and abs(o.y / U - pointer[1]) <= PIXEL / 2
        assert m.hand.position == (o.x, o.y)

    def test_hand_keeps_its_place_on_the_object(self):
        sc = scene(obj("square", "red", 0.52, 0.49), pointer=(0.3, 0.3))
        m, _ = run_both("scene_parse; grab_object; move_hand_to_pointer", sc)
        assert not m.failed
        o = slot(m, 0)
        assert abs(o.x / U - 0.3) <= PIXEL / 2 and abs(o.y / U - 0.3) <= PIXEL / 2
        assert (m.hand.position[0] - o.x, m.hand.position[1] - o.y) == (C - u(0.52), C - u(0.49))

    def test_stops_at_contact_on_the_way(self):
        sc = scene(obj("square", "red", 0.5, 0.5), obj("circle", "blue", 0.3, 0.5), pointer=(0.12, 0.5))
        m, _ = run_both("scene_parse; grab_object; move_hand_to_pointer", sc)
        assert not m.failed
        x, y = centre_of(m, 0)
        assert y == C and u(0.3) < x < C
        assert_no_overlap(m)
        assert_in_contact(m, 0, [(-1, 0)])

    def test_stops_at_workspace_edge(self):
        sc = scene(obj("square", "red", 0.5, 0.5), pointer=(0.0, 0.5))
        m, _ = run_both("scene_parse; grab_object; move_hand_to_pointer", sc)
        assert not m.failed and 0 <= slot(m, 0).x / U - 0.05 < PIXEL and slot(m, 0).y == C
        m.output_scene().validate()

    def test_fails_when_not_holding(self):
        sc = scene(obj("square", "red", 0.5, 0.5), pointer=(0.3, 0.3))
        m, _ = run_both("scene_parse; move_hand_to_pointer", sc)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "not holding an object"

    def test_fails_without_pointer(self):
        m, _ = run_both("scene_parse; grab_object; move_hand_to_pointer", CENTRED)
        assert m.failed and m.control.fail_index == 2 and m.fail_reason == "no pointer"


class TestMoveHandToFixateCollision:
    @pytest.mark.parametrize("pointer", [(0.7, 0.25), (0.33, 0.61)])
    def test_arrives_at_fovea(self, pointer):
        sc = scene(obj("square", "red", 0.5, 0.5), pointer=pointer)
        m, _ = run_both("scene_parse; fixate_pointer; grab_object; move_hand_to_fixate_collision", sc)
        assert not m.failed
        o = slot(m, 0)
        assert abs(o.x / U - pointer[0]) <= PIXEL / 2 and abs(o.y / U - pointer[1]) <= PIXEL / 2
        assert m.hand.position == (o.x, o.y) and m.fovea.position == (u(pointer[0]), u(pointer[1]))

    def test_uses_fovea_restored_by_fixate_previous(self):
        sc = scene(obj("square", "red", 0.5, 0.5), pointer=(0.7, 0.25))
        m, _ = run_both("scene_parse; fixate_pointer; fixate(bottom); fixate_previous; grab_object; "
                        "move_hand_to_fixate_collision", sc)
        o = slot(m, 0)
        assert abs(o.x / U - 0.7) <= PIXEL / 2 and abs(o.y / U - 0.25) <= PIXEL / 2

    def test_stops_at_workspace_edge(self):
        m, _ = run_both("scene_parse; fixate(left); grab_object; move_hand_to_fixate_collision", CENTRED)
        assert not m.failed and 0 <= slot(m, 0).x / U - slot(m, 0).width / 2 < PIXEL
        assert slot(m, 0).y == C
        m.output_scene().validate()

    def test_stops_at_contact_with_fixated_object(self):
        sc = scene(obj("square", "red", 0.5, 0.5), obj("triangle", "blue", 0.2, 0.8))
        m, _ = run_both("scene_parse; set_color_attn(blue); top_down_attend; fixate_attended_object; "
                        "grab_object; move_hand_to_fixate_collision", sc)
        assert not m.failed and m.hand.held == 0
        x, y = centre_of(m, 0)
        assert x < C and y > C
        assert_no_overlap(m)
        assert_in_contact(m, 0, [(-1, 0), (0, 1), (-1, 1)])

    def test_fails_when_not_holding(self):
        m, _ = run_both("scene_parse; fixate(left); move_hand_to_fixate_collision", CENTRED)
        assert m.failed and m.control.fail_index == 2 and m.fail_reason == "not holding an object"


