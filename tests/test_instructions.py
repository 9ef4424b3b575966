"""Every instruction of docs/vcc.md section 3: its effect and each of its failure rules.

Each test runs its program with `run_both`, so it also checks that the JAX emulator
and the reference interpreter agree on the whole machine state; the assertions are
then made on the reference machine `m` (positions in integer units: 1024 across).
Extra rules from docs/vcc.md are covered too: the fixation history cap, loop-body
rules, zero-iteration loops, failure indices inside loop replays, and the rules about
`scene_parse`.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from conftest import obj, run_both, scene

from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.geometry import imagined_pixels, object_pixels
from vccjax.machine.instructions import COLORS, FIXATE_TARGETS, IMAGINE_KINDS, NAMES, SHAPES, arg_domain
from vccjax.machine.scene import to_units

CFG = DEFAULT_CONFIG
U = CFG.units  # 1024 position units across
C = U // 2  # the centre, 512
R = CFG.raster  # 64 pixels
SUB = CFG.sub  # 16 units per pixel
PIXEL = 1 / R  # one pixel, in workspace coordinates
CENTRE = (C, C)


# ---- helpers ----------------------------------------------------------------------------
def u(v: float) -> int:
    """A workspace coordinate in integer units, as scene_parse rounds it."""
    return to_units(v, CFG)


def shape_id(name: str) -> int:
    return SHAPES.index(name)


def color_id(name: str) -> int:
    return COLORS.index(name)


def centre_of(m, i: int) -> tuple[int, int]:
    return m.centre(i)


def slot(m, i: int) -> SimpleNamespace:
    """Object slot i as the reference's blackboard holds it (centre in units)."""
    x, y = m.centre(i)
    b = m.blackboard
    return SimpleNamespace(shape=m.shapes[i], color=b.color[i], x=x, y=y, width=m.widths[i], alive=b.alive[i])


def colors(m) -> list[int]:
    """The scene's objects' colours on the blackboard."""
    return m.blackboard.color[: len(m.scene.objects)]


def imagined(m) -> tuple[int, int, int] | None:
    """(kind, x, y) of the imagined object, or None."""
    b = m.blackboard
    return None if b.imagined_kind < 0 else (b.imagined_kind, *b.imagined_position)


def mask(m, i: int, dx: int = 0, dy: int = 0) -> set[tuple[int, int]]:
    """(row, col) pixels of object i, shifted by (dx, dy) whole pixels, from geometry directly."""
    o = slot(m, i)
    rows, cols = object_pixels(SHAPES[o.shape], o.width, o.x + dx * SUB, o.y + dy * SUB, CFG)
    return set(zip(rows.tolist(), cols.tolist()))


def obstacles(m, i: int) -> set[tuple[int, int]]:
    """Pixels of every alive object except i, plus the imagined object's footprint."""
    out: set[tuple[int, int]] = set()
    for j in m.real_alive():
        if j != i:
            out |= mask(m, j)
    if imagined(m) is not None:
        rows, cols = imagined_pixels(*imagined(m), CFG)
        out |= set(zip(rows.tolist(), cols.tolist()))
    return out


def assert_no_overlap(m) -> None:
    """The output scene has no overlapping masks (and lies inside the workspace)."""
    m.output_scene().validate(CFG)
    held = m.hand.held
    if held >= 0:
        assert not (mask(m, held) & obstacles(m, held))


def assert_in_contact(m, i: int, steps: list[tuple[int, int]]) -> None:
    """Object i is stopped at contact: it overlaps nothing now, and one more pixel step in
    (one of) the given direction(s) would overlap another object or the imagined one."""
    blocked = obstacles(m, i)
    assert not (mask(m, i) & blocked), "the moved object overlaps something"
    assert any(mask(m, i, dx, dy) & blocked for dx, dy in steps), "the moved object is not in contact"


def box_gap(m, i, direction):
    """Distance from object i's w x w box to the workspace border on one side (>= 0)."""
    o = slot(m, i)
    x, y, h = o.x / U, o.y / U, o.width / 2
    gap = {"left": x - h, "right": 1 - x - h, "up": y - h, "down": 1 - y - h}[direction]
    assert gap >= 0
    return gap


def mask_extent(m, i: int) -> tuple[int, int, int, int]:
    rows, cols = zip(*mask(m, i))
    return min(rows), max(rows), min(cols), max(cols)


def alive_ids(m) -> list[int]:
    return m.real_alive()


def with_arg(name: str) -> str:
    dom = arg_domain(name)
    return f"{name}({dom[0]})" if dom else name


# ---- shared scenes ----------------------------------------------------------------------
# slot 1 nearest the centre, then slot 2, then slot 0
THREE = scene(
    obj("square", "red", 0.1, 0.1),
    obj("circle", "green", 0.6, 0.5),
    obj("diamond", "blue", 0.5, 0.8),
)

# two squares and two circles, two red and two blue; distances from the centre all differ
FILTER_SCENE = scene(
    obj("square", "red", 0.2, 0.2),  # 0: dist .424
    obj("square", "blue", 0.75, 0.25),  # 1: dist .354
    obj("circle", "red", 0.25, 0.72),  # 2: dist .333
    obj("circle", "blue", 0.6, 0.55),  # 3: dist .112
)

# one square at the exact centre (under the hand at start)
CENTRED = scene(obj("square", "red", 0.5, 0.5))


# =========================================================================================
# scene_parse and the rules around it
# =========================================================================================
class TestSceneParse:
    def test_loads_objects_and_pointer(self):
        sc = scene(obj("star", "yellow", 0.25, 0.75), obj("triangle", "blue", 0.7, 0.3),
                   pointer=(0.3, 0.6))
        m, _ = run_both("scene_parse", sc)
        assert not m.failed and m.blackboard.parsed
        assert [(o.shape, o.color, o.x, o.y, o.alive) for o in (slot(m, 0), slot(m, 1))] == [
            (shape_id("star"), color_id("yellow"), 256, 768, True),
            (shape_id("triangle"), color_id("blue"), u(0.7), u(0.3), True),
        ]
        assert m.pointer == (u(0.3), u(0.6))
        # the rest of the machine is in its initial state
        assert m.fovea.position == CENTRE and m.fovea.history == [CENTRE] and m.fovea.history_index == 0
        assert m.hand.position == CENTRE and m.hand.held < 0 and m.attention.attended < 0
        assert m.attention.stale and m.attention.cursor == 0 and m.blackboard.imagined_kind < 0
        out = m.output_scene().objects
        assert [(o.shape, o.color, o.width) for o in out] == [(o.shape, o.color, o.width) for o in sc.objects]
        # positions are rounded to the nearest unit (at most half a unit off)
        assert all(abs(a.x - b.x) <= 0.5 / U and abs(a.y - b.y) <= 0.5 / U for a, b in zip(out, sc.objects))

    def test_empty_scene_parses(self):
        m, _ = run_both("scene_parse", scene())
        assert not m.failed and m.blackboard.parsed and alive_ids(m) == []

    def test_second_scene_parse_fails(self):
        m, _ = run_both("scene_parse; fixate(left); scene_parse", THREE)
        assert m.failed and m.control.fail_index == 2
        assert "scene_parse" in m.fail_reason

    @pytest.mark.parametrize("name", [n for n in NAMES if n != "scene_parse"])
    def test_every_instruction_before_scene_parse_fails(self, name):
        sc = scene(obj("square", "red", 0.5, 0.5), pointer=(0.5, 0.5))
        m, st = run_both(f"{with_arg(name)}; scene_parse", sc)
        assert m.failed and m.control.fail_index == 0
        assert m.fail_reason == "no scene parsed yet"
        assert not m.blackboard.parsed and int(st.control.fail_index) == 0

    def test_failed_machine_ignores_later_instructions(self):
        m, st = run_both("scene_parse; release_object; fixate(left); top_down_attend", THREE)
        assert m.failed and m.control.fail_index == 1
        assert m.fovea.history == [CENTRE] and m.attention.attended < 0
        # the JAX state also stayed as it was before the failure
        assert int(st.fovea.history_len) == 1 and int(st.attention.attended) == -1 and int(st.control.fail_index) == 1

    def test_failing_instruction_leaves_jax_state_unchanged(self):
        m, st = run_both("scene_parse; fixate(left); fixate_next", THREE)
        assert m.failed and m.control.fail_index == 2
        assert m.fovea.position == (0, C) and m.fovea.history_index == 1
        assert tuple(int(v) for v in st.fovea.position) == (0, C)
        assert int(st.fovea.history_index) == 1 and int(st.fovea.history_len) == 2


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


# =========================================================================================
# fovea: fixate, fixate_attended_object, fixate_pointer, fixate_previous, fixate_next
# =========================================================================================
class TestFixate:
    @pytest.mark.parametrize(
        "target, expected",
        [("left", (0, 512)), ("right", (1024, 512)), ("top", (512, 0)), ("bottom", (512, 1024)),
         ("center", (512, 512))],
    )
    def test_targets(self, target, expected):
        m, _ = run_both(f"scene_parse; fixate({target})", THREE)
        assert not m.failed
        assert m.fovea.position == expected and m.fovea.history == [CENTRE, expected] and m.fovea.history_index == 1

    def test_appends_to_history(self):
        m, _ = run_both("scene_parse; fixate(left); fixate(top); fixate(left)", THREE)
        f = m.fovea
        assert f.history == [CENTRE, (0, C), (C, 0), (0, C)] and f.history_index == 3 and f.position == (0, C)

    def test_history_holds_hist_max_fixations(self):
        assert CFG.hist_max == 32
        targets = [FIXATE_TARGETS[i % 4] for i in range(CFG.hist_max - 1)]
        m, _ = run_both("scene_parse; " + "; ".join(f"fixate({t})" for t in targets), THREE)
        assert not m.failed and len(m.fovea.history) == CFG.hist_max and m.fovea.history_index == CFG.hist_max - 1

    @pytest.mark.parametrize("last", ["fixate(bottom)", "fixate_attended_object", "fixate_pointer"])
    def test_fixation_beyond_hist_max_fails(self, last):
        # four iterations of a body with 8 fixations: the 32nd fixation (history already
        # holds 32 entries, the initial centre included) fails at its body index, 10
        sc = scene(obj("square", "red", 0.2, 0.2), obj("circle", "green", 0.8, 0.2),
                   obj("diamond", "blue", 0.2, 0.8), obj("star", "yellow", 0.8, 0.8), pointer=(0.4, 0.6))
        body = "; ".join(["top_down_attend"] + ["fixate(left)"] * 7 + [last, "next_object"])
        m, _ = run_both(f"scene_parse; loop_start; {body}; loop_end", sc)
        assert m.failed and m.control.fail_index == 10 and "history full" in m.fail_reason
        assert len(m.fovea.history) == CFG.hist_max

    def test_three_iterations_fit_the_history(self):
        sc = scene(obj("square", "red", 0.2, 0.2), obj("circle", "green", 0.8, 0.2),
                   obj("diamond", "blue", 0.2, 0.8))
        body = "; ".join(["top_down_attend"] + ["fixate(left)"] * 7 + ["fixate_attended_object", "next_object"])
        m, _ = run_both(f"scene_parse; loop_start; {body}; loop_end", sc)
        assert not m.failed and len(m.fovea.history) == 25 and m.attention.cursor == 3


class TestFixateAttendedObject:
    def test_fixates_attended_centre(self):
        sc = scene(obj("triangle", "red", 0.3, 0.7), obj("circle", "blue", 0.9, 0.9))
        m, _ = run_both("scene_parse; top_down_attend; fixate_attended_object", sc)
        assert not m.failed
        f = m.fovea
        assert f.position == (u(0.3), u(0.7)) and f.history == [CENTRE, (u(0.3), u(0.7))] and f.history_index == 1

    def test_follows_moved_object(self):
        m, _ = run_both("scene_parse; grab_object; move_hand_up; top_down_attend; fixate_attended_object",
                        CENTRED)
        assert not m.failed and m.fovea.position == centre_of(m, 0) and m.fovea.position[1] < C

    def test_fails_without_attended_object(self):
        m, _ = run_both("scene_parse; fixate_attended_object", THREE)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "no attended object"

    def test_fails_after_next_object(self):
        m, _ = run_both("scene_parse; top_down_attend; next_object; fixate_attended_object", THREE)
        assert m.failed and m.control.fail_index == 3


class TestFixatePointer:
    def test_fixates_pointer(self):
        sc = scene(obj("circle", "blue", 0.8, 0.8), pointer=(0.3, 0.7))
        m, _ = run_both("scene_parse; fixate_pointer", sc)
        f = m.fovea
        assert not m.failed and f.position == (u(0.3), u(0.7)) and f.history[-1] == f.position and f.history_index == 1

    def test_fails_without_pointer(self):
        m, _ = run_both("scene_parse; fixate_pointer", THREE)
        assert m.failed and m.control.fail_index == 1 and m.fail_reason == "no pointer"


class TestFixatePrevious:
    def test_walks_back_without_changing_history(self):
        m, _ = run_both("scene_parse; fixate(left); fixate(top); fixate_previous", THREE)
        assert not m.failed and m.fovea.position == (0, C) and m.fovea.history_index == 1
        assert m.fovea.history == [CENTRE, (0, C), (C, 0)]
        m, _ = run_both("scene_parse; fixate(left); fixate(top); fixate_previous; fixate_previous", THREE)
        assert m.fovea.position == CENTRE and m.fovea.history_index == 0 and len(m.fovea.history) == 3

    def test_fails_at_start_of_history(self):
        m, _ = run_both("scene_parse; fixate_previous", THREE)
        assert m.failed and m.control.fail_index == 1 and "previous" in m.fail_reason
        m, _ = run_both("scene_parse; fixate(left); fixate_previous; fixate_previous", THREE)
        assert m.failed and m.control.fail_index == 3

    def test_new_fixation_after_walking_back_appends(self):
        m, _ = run_both("scene_parse; fixate(left); fixate(right); fixate_previous; fixate_previous; "
                        "fixate(top)", THREE)
        f = m.fovea
        assert f.history == [CENTRE, (0, C), (U, C), (C, 0)] and f.history_index == 3 and f.position == (C, 0)

    def test_attention_refresh_uses_restored_fovea(self):
        m, _ = run_both("scene_parse; fixate(left); fixate(right); fixate_previous; top_down_attend", THREE)
        assert m.fovea.position == (0, C) and m.attention.attended_list == [0, 2, 1]


class TestFixateNext:
    def test_walks_forward_without_changing_history(self):
        m, _ = run_both("scene_parse; fixate(left); fixate(top); fixate_previous; fixate_previous; "
                        "fixate_next", THREE)
        assert not m.failed and m.fovea.position == (0, C) and m.fovea.history_index == 1
        assert m.fovea.history == [CENTRE, (0, C), (C, 0)]
        m, _ = run_both("scene_parse; fixate(left); fixate(top); fixate_previous; fixate_previous; "
                        "fixate_next; fixate_next", THREE)
        assert m.fovea.position == (C, 0) and m.fovea.history_index == 2 and len(m.fovea.history) == 3

    def test_fails_at_end_of_history(self):
        m, _ = run_both("scene_parse; fixate_next", THREE)
        assert m.failed and m.control.fail_index == 1 and "next" in m.fail_reason
        m, _ = run_both("scene_parse; fixate(left); fixate_previous; fixate_next; fixate_next", THREE)
        assert m.failed and m.control.fail_index == 4


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
