"""The robot: camera to scene, VCC plan to arm motion, physics on C MuJoCo and MJX, judging."""

from __future__ import annotations

import numpy as np
import pytest

import robot  # noqa: F401  (sets MUJOCO_GL before mujoco is imported)
from robot.judge import CAUSES, judge
from robot.control import CHUNK, RECORD
from robot.motion import keyframes
from robot.plan import PlanError, grip_yaw, plan
from robot.reference import rollout as c_rollout
from robot.rollout import Bench, scenarios_for
from robot.scenario import draw
from robot.world import to_table, to_workspace
from vccjax.world.concepts import reference_program
from vccjax.machine.program import parse
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, SceneObject, scenes_match

STACK = "stack_in_place_horizontal_left"
POINTED = "move_bottom_to_pointed"


@pytest.fixture(scope="module")
def bench():
    return Bench()


def test_workspace_and_table_coordinates_round_trip():
    uv = np.random.default_rng(0).uniform(0, 1, (20, 2))
    xy = to_table(uv[:, 0], uv[:, 1])
    np.testing.assert_allclose(to_workspace(xy[:, 0], xy[:, 1]), uv, atol=1e-12)
    # image up is away from the arm (+x), image right is the arm's right (-y)
    assert to_table(0.5, 0.0)[0] > to_table(0.5, 1.0)[0] and to_table(1.0, 0.5)[1] < to_table(0.0, 0.5)[1]


def test_a_rendered_camera_frame_parses_to_the_scenario(bench):
    for seed, concept in enumerate([POINTED, STACK, POINTED]):
        sc = draw(reference_program(concept), seed)
        d = bench.data
        d.qpos[:] = sc.qpos(bench.model)
        sc.dress(bench.model, d)
        import mujoco

        mujoco.mj_forward(bench.model, d)
        parsed, view = bench.camera.scene(d)
        assert view.shape == (384, 384, 3)
        assert scenes_match(parsed, sc.scene, 0.02), (parsed, sc.scene)
        assert (parsed.pointer is None) == (sc.scene.pointer is None)
        if parsed.pointer is not None:
            assert np.hypot(*np.subtract(parsed.pointer, sc.scene.pointer)) < 0.02


def test_plan_carries_each_moved_object_to_the_vcc_output():
    program = reference_program(STACK)
    second = reference_program("move_green_to_right_bottom_corner")
    scene = draw([program, second], 3).scene  # a table on which both run
    moves, out = plan(program, scene)
    expected = RefMachine(scene).run(program).output_scene()
    assert out == expected and moves
    for mv in moves:
        assert mv.path[0] == pytest.approx((scene.objects[mv.slot].x, scene.objects[mv.slot].y), abs=1e-3)
        assert mv.path[-1] == pytest.approx((out.objects[mv.slot].x, out.objects[mv.slot].y), abs=1e-3)
    # a composition runs the second program on the first one's output
    both, out2 = plan([program, second], scene)
    assert both[: len(moves)] == moves and out2 == RefMachine(out).run(second).output_scene()


def test_plan_refuses_what_no_arm_can_do():
    scene = Scene((SceneObject("square", "red", 0.3, 0.3, 0.1), SceneObject("circle", "blue", 0.7, 0.7, 0.1)))
    with pytest.raises(PlanError, match="fill_color recolours an object"):
        plan(parse("scene_parse; top_down_attend; fill_color(green)"), scene)
    with pytest.raises(PlanError, match="failed at instruction 1"):
        plan(parse("scene_parse; grab_object"), scene)


def test_grip_yaw_keeps_the_pads_off_a_neighbour():
    # a square set down just left of another: the fingers must close along the column, not the row
    from robot.plan import PickPlace

    mv = PickPlace(0, "square", 0.1, ((0.2, 0.5), (0.5, 0.5)), (), ((0.61, 0.5, 0.1, "square"),))
    yaw = grip_yaw(mv)
    du, dv = -np.sin(yaw), -np.cos(yaw)  # the finger axis in workspace terms
    assert abs(du) < 1e-6 and abs(abs(dv) - 1) < 1e-6


def test_keyframes_are_in_order_and_padded(bench):
    program = reference_program(STACK)
    sc = draw(program, 1)
    moves, _ = plan(program, sc.scene)
    kf, ticks, windows = keyframes(moves, np.array([0.13, -0.49, 0.37]), np.pi)
    assert (np.diff(kf.tick) > 0).all() and kf.tick.shape == kf.yaw.shape == kf.grip.shape
    assert len(windows) == len(moves) and all(0 < a < b <= ticks for a, b in windows)
    assert kf.pos[:, 2].min() > 0.0  # never into the table


def test_a_c_mujoco_rollout_succeeds_and_a_gripper_that_never_closes_slips(bench):
    program = reference_program(POINTED)
    sc = scenarios_for(program, 1, seed=0)[0]
    prepared = bench.prepare(program, sc)
    assert prepared.error is None
    ticks = (prepared.ticks // RECORD + 6) * RECORD
    qs = c_rollout(bench.model, sc.qpos(bench.model), prepared.keyframes, ticks, RECORD)
    verdict = judge(bench.model, prepared, qs)
    assert verdict.success, verdict
    assert np.isfinite(qs).all()
    import dataclasses

    never = dataclasses.replace(prepared.keyframes, grip=np.full_like(prepared.keyframes.grip, 0.04))
    qs = c_rollout(bench.model, sc.qpos(bench.model), never, ticks, RECORD)
    bad = judge(bench.model, dataclasses.replace(prepared, keyframes=never), qs)
    assert not bad.success and bad.cause == "grasp slipped"
    broken = qs.copy()
    broken[-1, 0] = np.nan  # NaN compares false: without its own check it would pass as a success
    v = judge(bench.model, prepared, broken)
    assert not v.success and v.cause == "non-finite state"


def test_a_scene_the_camera_cannot_parse_is_a_parse_error(bench, monkeypatch):
    from vccjax.errors import SceneError

    program = reference_program(POINTED)
    sc = scenarios_for(program, 1, seed=2)[0]

    def blind(data):
        raise SceneError("no objects found in the image")

    monkeypatch.setattr(bench.camera, "scene", blind)
    p = bench.prepare(program, sc)
    v = judge(bench.model, p, None)
    assert not v.success and v.cause == "parse error" and "no objects" in v.detail


def test_a_parse_that_misses_an_object_is_a_failure_of_its_own(bench, monkeypatch):
    """The arm must not be judged against a wrong parse: dropping one object of the true
    scene, or reading a colour wrong, fails as "parse wrong" before anything moves."""
    import dataclasses

    program = reference_program(POINTED)
    sc = scenarios_for(program, 1, seed=2)[0]
    seen = {"scene": dataclasses.replace(sc.scene, objects=sc.scene.objects[1:])}
    monkeypatch.setattr(bench.camera, "scene", lambda data: (seen["scene"], None))
    v = judge(bench.model, bench.prepare(program, sc), None)
    assert not v.success and v.cause == "parse wrong" and "1 of" in v.detail and "not seen" in v.detail
    assert v.parse["found"] == len(sc.scene.objects) - 1 and not v.parse["exact"]
    other = {"red": "green", "green": "blue", "blue": "yellow", "yellow": "red"}
    o = sc.scene.objects[0]
    seen["scene"] = dataclasses.replace(sc.scene, objects=(dataclasses.replace(o, color=other[o.color]),
                                                           *sc.scene.objects[1:]))
    v = judge(bench.model, bench.prepare(program, sc), None)
    assert v.cause == "parse wrong" and "colour" in v.detail
    seen["scene"] = sc.scene  # the truth itself: the parse check passes
    p = bench.prepare(program, sc)
    assert p.error is None and p.check.exact and sorted(p.check.match) == list(range(len(sc.scene.objects)))


@pytest.mark.parametrize("shape", ["triangle", "star"])
def test_triangles_and_stars_are_plates_the_camera_parses_and_the_arm_carries(bench, shape):
    """A concept that names a triangle or a star runs: its body is a plate of that outline
    with a knob, the camera parses it as that shape, and the arm carries it by the knob
    (C MuJoCo, the controller MJX is tested against)."""
    program = parse(f"scene_parse; set_shape_attn({shape}); top_down_attend; move_hand_to_attended_object; "
                    "grab_object; move_hand_left; release_object")
    for seed in range(2):
        sc = draw(program, seed)
        assert shape in {o.shape for o in sc.scene.objects}
        p = bench.prepare(program, sc)
        assert p.error is None and p.check.exact, p.error
        ticks = (p.ticks // RECORD + 6) * RECORD
        qs = c_rollout(bench.model, sc.qpos(bench.model), p.keyframes, ticks, RECORD)
        v = judge(bench.model, p, qs)
        assert v.success, v


def test_a_plates_mesh_is_its_vcc_outline_with_outward_faces():
    """The plate's vertices trace the VCC's own outline (image up = world +x), and every
    face of its mesh points out of the plate (so that it renders, and its hull is right)."""
    from robot.mjcf import mesh_faces, mesh_vertices
    from robot.world import BODIES
    from vccjax.machine.geometry import star_polygon

    for body in (b for b in BODIES if b.knob):
        v, f = mesh_vertices(body), mesh_faces(body)
        top = v[v[:, 2] > 0][:-1]  # the outline at the top, the centre left out
        r = body.size / 2
        img = star_polygon(r) if body.kind == "star" else np.array([[0.0, -r], [-r, r], [r, r]])
        expect = {(round(-y, 9), round(-x, 9)) for x, y in img}
        assert {(round(a, 9), round(b, 9)) for a, b in top[:, :2]} == expect
        centroid = v.mean(0)
        for a, b, c in f:
            normal = np.cross(v[b] - v[a], v[c] - v[a])
            mid = (v[a] + v[b] + v[c]) / 3
            side = mid - centroid
            side[:2] = np.where(abs(normal[2]) > 1e-12, 0.0, side[:2])  # top and bottom: only z says out
            assert np.dot(normal, side) > 0


def test_mjx_rollout_agrees_with_the_c_reference(bench):
    """gymnax-style: the batched MJX rollout against the NumPy controller on C MuJoCo."""
    import jax
    import jax.numpy as jnp

    program = reference_program(POINTED)
    sc = scenarios_for(program, 1, seed=0)[0]
    p = bench.prepare(program, sc)
    q0 = sc.qpos(bench.model)
    kf = jax.tree.map(lambda x: jnp.asarray(np.asarray(x)[None]), p.keyframes)
    got = bench.arm.rollout(jnp.asarray(q0[None]), kf, 1)[0]  # one compiled chunk: the first 5 s
    ref = c_rollout(bench.model, q0, p.keyframes, CHUNK, RECORD)
    assert got.shape == ref.shape
    arm = bench.arm.arm_qpos
    np.testing.assert_allclose(got[:24, arm], ref[:24, arm], atol=2e-3)  # radians, the free move (2.4 s)
    from robot.judge import _slot_xyz

    np.testing.assert_allclose(_slot_xyz(bench.model, got[-1]), _slot_xyz(bench.model, ref[-1]), atol=5e-3)
    assert np.isfinite(got).all()


def test_robot_cli_errors_are_one_line(capsys):
    from vcc.cli import main

    for argv, message in [
        (["robot", "run", "--concept", "no_such_concept"], "unknown concept 'no_such_concept'"),
        (["robot", "run", "--concept", "x", "--program", "scene_parse; jump"], "unknown instruction"),
        (["robot", "run", "--concept", POINTED, "--frames", "f.gif"], "argument --frames: f.gif: write .png or .jpg"),
        (["robot", "run", "--concept", POINTED, "--video", "v.mov"], "argument --video: v.mov: write .mp4 or .avi"),
        (["robot", "run", "--concept", POINTED, "--scenarios", "0"], "argument --scenarios: 0 is out of range"),
        (["robot", "suite", "--out", "x", "--concepts", "no_such_concept"], "no_such_concept: not induced in"),
        (["robot", "suite", "--out", "x", "--concepts", "change_all_objs_color"], "recolours"),
        (["robot", "suite", "--out", "x", "--shard", "2/2"], "--shard 2/2: K must be in 0..N-1"),
        (["robot", "suite", "--out", "x", "--shard", "half"], "--shard half: give K/N"),
        (["robot", "suite", "--out", "x", "--source", "no/such/run"], "results.jsonl: missing"),
        (["robot", "suite", "--out", "x", "--scenarios", "0"], "argument --scenarios: 0 is out of range"),
    ]:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.startswith("vcc") and ": error: " in err and message in err and err.count("\n") == 1, err


def test_run_reads_a_long_program_as_text_a_file_as_a_file_and_refuses_a_missing_file(tmp_path, capsys):
    """`--program` given a long program's text (once an OSError: file name too long), an
    existing file, and a .vcc file that is not there; no MuJoCo runs."""
    import argparse
    import os

    from robot.cli import _program
    from vcc.cli import main

    steps = ["scene_parse", "set_color_attn(red)", "top_down_attend", "move_hand_to_attended_object", "grab_object",
             "move_hand_left", "release_object"]
    text = "; ".join(steps + steps[1:] * 6)
    assert len(text) >= 400
    args = argparse.Namespace(program=text, concept="x", induced=None)
    got = _program(args)
    assert got == parse(text) and len(got) == len(steps) + 6 * (len(steps) - 1)
    short = "scene_parse; top_down_attend; move_hand_to_attended_object; grab_object; move_hand_left"
    for name in ("p", "p.vcc"):
        (tmp_path / name).write_text(short + "\n")
        assert _program(argparse.Namespace(program=str(tmp_path / name), concept="x", induced=None)) == parse(short)
    cores = os.sched_getaffinity(0) if hasattr(os, "sched_getaffinity") else None
    missing = tmp_path / "none.vcc"
    assert main(["robot", "run", "--concept", "x", "--program", str(missing)]) == 2
    err = capsys.readouterr().err
    assert err == f"vcc: error: {missing}: no such program file\n"
    assert not missing.exists()
    if cores is not None:  # refused before the process was set up (pinned to one core) for MJX
        assert os.sched_getaffinity(0) == cores


def test_importing_mjx_does_not_print_that_the_optional_warp_is_missing():
    import importlib.util
    import subprocess
    import sys
    from pathlib import Path

    from robot import _without_warp_absent

    code = "import robot.control, mujoco.mjx.warp as w; print('warp installed:', w.WARP_INSTALLED)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                       cwd=Path(__file__).parents[2])
    assert r.returncode == 0, r.stderr
    have_warp = importlib.util.find_spec("warp") is not None
    assert r.stdout == f"warp installed: {have_warp}\n" and "Failed to import" not in r.stderr, (r.stdout, r.stderr)
    # only mujoco's two lines for an absent warp are dropped; anything else it prints stays
    printed = ("Failed to import warp: No module named 'warp'\n"
               "Failed to import mujoco_warp: No module named 'warp'\n"
               "Failed to import warp: CUDA driver too old\n")
    assert _without_warp_absent(printed) == "Failed to import warp: CUDA driver too old\n"


def test_video_of_a_rollout_is_written(bench, tmp_path):
    from robot.video import write_video

    program = reference_program(POINTED)
    sc = scenarios_for(program, 1, seed=0)[0]
    p = bench.prepare(program, sc)
    qs = c_rollout(bench.model, sc.qpos(bench.model), p.keyframes, 40, 10)
    path = tmp_path / "one.mp4"
    assert write_video(bench.model, sc, qs, path, 10, size=120) == 4
    import cv2

    cap = cv2.VideoCapture(str(path))
    ok, frame = cap.read()
    assert ok and frame.shape == (120, 212, 3)
    from robot.video import write_frames

    strip = tmp_path / "frames.png"
    assert write_frames(bench.model, sc, qs, strip, count=3, size=60) == 3
    assert cv2.imread(str(strip)).shape == (60, 3 * 80 + 2 * 4, 3)  # three 80 x 60 frames, 4-pixel gaps
    with pytest.raises(ValueError, match="write .png or .jpg"):
        write_frames(bench.model, sc, qs, tmp_path / "frames.gif")


@pytest.mark.slow
def test_a_thousand_random_rollouts_stay_finite(tmp_path):
    """1,000 rollouts of random arm-compatible concepts on random scenarios, 32 at a time
    on MJX (`vcc robot stress`): every state finite, every scenario judged (about an hour
    and a half on one core)."""
    from robot.sources import RUN_OF_RECORD, Programs
    from robot.stress import run_stress

    s = run_stress(tmp_path, Programs(str(RUN_OF_RECORD)), rollouts=1000, seed=7, log=lambda _: None)
    assert s["rollouts"] >= 1000 and s["non_finite"] == 0
    assert s["rolled_out"] > 0.9 * s["rollouts"] and set(s["failures"]) <= set(CAUSES)


def test_a_batch_is_padded_to_one_size_and_the_copies_thrown_away(bench, monkeypatch):
    """MJX compiles once per batch size: a suite batch is always rolled out at `pad_to`,
    however many scenarios the parse or the plan refused, and only the real ones judged."""
    program = reference_program(POINTED)
    scenarios = scenarios_for(program, 3, seed=0)
    shapes = []

    class FakeArm:
        def compile(self, q0, kf):
            shapes.append(q0.shape[0])

        def rollout(self, q0, kf, ticks):
            return np.repeat(np.asarray(q0)[:, None, :], 2, axis=1)  # stands still: every verdict a failure

    monkeypatch.setattr(bench, "arm", FakeArm())
    verdicts, info, kept = bench.run_pairs([(program, s) for s in scenarios], keep=True, pad_to=8)
    assert shapes == [8] and len(verdicts) == len(kept) == 3 and info["scenarios"] == 3
    assert all(q is not None and q.shape[0] == 2 for q in kept)
