"""Instructions of docs/vcc.md section 3, scene_parse and the rules around it.

Each test runs its program on both machines (`run_both`), so it also checks that they
agree on the whole state; assertions are made on the reference machine `m`.
"""

from __future__ import annotations

import pytest

from tests.machine.instruction_helpers import (
    alive_ids,
    C,
    CENTRE,
    color_id,
    NAMES,
    obj,
    run_both,
    scene,
    shape_id,
    slot,
    THREE,
    U,
    u,
    with_arg,
)


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


