"""Traces: every executed instruction recorded in order (loop iterations included), the
failure where it happened, and the drawings (`vcc trace`) written as PNG and GIF."""

from __future__ import annotations

import numpy as np
import pytest

from vccjax.world.concepts import reference_program
from vccjax.world.dataset import dataset_for
from vccjax.machine.program import parse
from vccjax.machine.reference import run_reference
from vccjax.machine.scene import Scene, SceneObject, scenes_match
from vccjax.views.trace import trace
from vccjax.views.viewer import RED, panel, sheet, write_trace

SWAP = "swap_locations"


@pytest.fixture(scope="module")
def swap_scene() -> Scene:
    return dataset_for([SWAP], 0, None, progress=False).pairs(SWAP, "test")[0][0]


def test_trace_records_each_instruction_and_ends_where_the_run_ends(swap_scene):
    program = reference_program(SWAP)
    frames = trace(program, swap_scene)
    assert [f.instruction for f in frames] == ["input"] + program.text().split("; ")
    assert [f.pc for f in frames] == list(range(-1, len(program)))
    final = frames[-1].machine.output_scene()
    assert scenes_match(final, run_reference(program, swap_scene).output_scene(), 1e-9)
    assert not scenes_match(final, swap_scene, 0.02)  # the swap moved something
    assert not frames[0].machine.blackboard.parsed  # the input frame: nothing parsed yet
    assert not any(frames[0].machine.blackboard.alive)


def test_loop_iterations_appear_in_the_trace():
    scene = Scene(tuple(SceneObject("circle", "red", x, 0.5, 0.1) for x in (0.2, 0.5, 0.8)))
    program = parse("scene_parse; loop_start; top_down_attend; fill_color(blue); next_object; loop_end")
    frames = trace(program, scene)
    fills = [f for f in frames if f.instruction == "fill_color(blue)"]
    assert [f.iteration for f in fills] == [0, 1, 2]  # three objects, three times round
    assert frames[-1].instruction == "loop_end"
    assert frames[-1].machine.blackboard.color[:3] == [2, 2, 2]  # all blue
    assert fills[0].machine.blackboard.color[:3].count(2) == 1  # snapshots, not one shared machine


def test_a_failing_instruction_ends_the_trace_marked():
    scene = Scene((SceneObject("square", "green", 0.3, 0.3, 0.1),))
    frames = trace(parse("scene_parse; grab_object; move_hand_left"), scene)
    assert [f.instruction for f in frames] == ["input", "scene_parse", "grab_object"]
    assert frames[-1].failed and not frames[-2].failed
    assert "no object at the hand" in frames[-1].machine.fail_reason
    img = panel(frames[-1], size=128)
    assert (img[0, :] == RED).all() and not (panel(frames[-2], size=128)[0, :] == RED).all()


def test_png_sheet_and_gif_are_written(swap_scene, tmp_path):
    from PIL import Image

    frames = trace(reference_program(SWAP), swap_scene)
    one = panel(frames[3], size=128)
    assert one.dtype == np.uint8 and one.shape[2] == 3 and one.shape[1] == 128 + 12
    s = sheet(frames, size=128, columns=6)
    rows = -(-len(frames) // 6)
    assert s.shape == (rows * (one.shape[0] + 4), 6 * (one.shape[1] + 4), 3)
    png = write_trace(frames, tmp_path / "t.png", size=128)
    gif = write_trace(frames, tmp_path / "t.gif", size=128)
    assert Image.open(png).size == (s.shape[1], s.shape[0])
    with Image.open(gif) as g:
        assert g.n_frames == len(frames) and g.size == (one.shape[1], one.shape[0])
    with pytest.raises(ValueError, match=r"\.png or \.gif"):
        write_trace(frames, tmp_path / "t.jpg")


def test_vcc_trace_writes_both_for_swap_locations(tmp_path, capsys):
    from vcc.cli import main

    png, gif = tmp_path / "swap.png", tmp_path / "swap.gif"
    argv = ["trace", "--concept", SWAP, "--example", "0", "--split", "test", "--out", f"{png},{gif}", "--size", "96"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "test example 0 of swap_locations" in out and "ran to the end" in out
    assert png.stat().st_size > 1000 and gif.stat().st_size > 1000
    assert main(["trace", "scene_parse; release_object", "--out", str(tmp_path / "f.png"), "--size", "96"]) == 1
    assert "FAILED at instruction 1 (release_object)" in capsys.readouterr().out
