"""Instructions of docs/vcc.md section 3, the fovea: fixations and the fixation history.

Each test runs its program on both machines (`run_both`), so it also checks that they
agree on the whole state; assertions are made on the reference machine `m`.
"""

from __future__ import annotations

import pytest

from tests.machine.instruction_helpers import (
    C,
    CENTRE,
    centre_of,
    CENTRED,
    CFG,
    FIXATE_TARGETS,
    obj,
    run_both,
    scene,
    THREE,
    U,
    u,
)


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


