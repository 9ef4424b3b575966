"""The `vcc` command: demo output, and one-line errors (exit code 2) for user mistakes."""

from __future__ import annotations

import json
from pathlib import Path

from vcc.cli import main


def test_run_concept_prints_before_and_after(capsys):
    assert main(["run", "--concept", "move_to_middle", "--engine", "reference"]) == 0
    out = capsys.readouterr().out
    assert "before" in out and "after" in out and out.strip().endswith("changed")


def test_a_saved_concept_that_changes_nothing_runs_on_the_first_scene_it_runs_on(capsys, tmp_path, monkeypatch):
    """A concept that never changes a table ("leave it as it is", learned as "grab the
    star") is shown on the first seed it runs on, and says so, not on a seed it fails on."""
    import numpy as np

    from vccjax.machine.program import parse
    from vccjax.machine.reference import run_reference
    from vccjax.world.scenes import random_scene
    from vccjax.world.user_concepts import save_concept

    text = "scene_parse; set_shape_attn(star); top_down_attend; move_hand_to_attended_object; grab_object"
    monkeypatch.setenv("VCC_LIBRARY", str(tmp_path))
    save_concept("grab_star", {"program": text}, tmp_path)
    scenes = [random_scene(np.random.default_rng(s), 4, pointer=True) for s in range(500)]  # as `vcc run` draws
    runs = [s for s, scene in enumerate(scenes) if not run_reference(parse(text), scene).failed]
    assert main(["run", "--concept", "grab_star", "--engine", "reference"]) == 0
    out = capsys.readouterr().out
    assert f"random scene, seed {runs[0]} (grab_star changes no scene of seeds 0 to 499; the first it runs on)" in out


def test_concepts_says_when_no_name_matches(capsys):
    assert main(["concepts", "no_concept_is_named_so"]) == 0
    out = capsys.readouterr().out
    assert out == "no concept name contains 'no_concept_is_named_so' (vcc concepts alone lists all 546)\n"
    assert main(["concepts", "swap"]) == 0
    assert "swap_locations" in capsys.readouterr().out


def test_run_reports_a_failing_program(capsys):
    assert main(["run", "scene_parse; release_object", "--engine", "reference"]) == 1
    assert "FAILED at instruction 1 (release_object): not holding an object" in capsys.readouterr().out


def test_user_mistakes_are_one_line_errors(capsys, tmp_path):
    cases = [
        (["run", "scene_parse; jump"], "unknown instruction or subroutine 'jump'"),
        (["run", "--concept", "no_such_concept"], "unknown concept 'no_such_concept'"),
        (["run"], "give a PROGRAM, or --concept NAME"),
        (["run", "scene_parse", "--scene", str(tmp_path / "none.json")], "no such scene file"),
        (["run", str(tmp_path / "missing.vcc")], "no such program file"),
        (["dataset", "info", str(tmp_path)], "manifest.json: missing"),
    ]
    for argv, message in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.startswith("vcc: error: ") and message in err and err.count("\n") == 1, err


def test_scene_sources_and_their_mistakes_are_one_line_errors(capsys, tmp_path):
    """--image, --example and --dataset: a file that is missing, unreadable, empty of
    objects, or a corrupt dataset, each ends in one line and exit code 2."""
    import shutil

    import cv2
    import numpy as np

    from vccjax.world.dataset import shipped_folder

    argv = ["run", "--concept", "swap_locations", "--example", "2", "--split", "test", "--engine", "reference"]
    assert main(argv) == 0
    assert "test example 2 of swap_locations" in (out := capsys.readouterr().out) and "output: matched" in out
    blank, junk = tmp_path / "blank.png", tmp_path / "junk.png"
    cv2.imwrite(str(blank), np.full((80, 80, 3), 255, np.uint8))
    junk.write_text("not an image")
    bad = tmp_path / "dataset"
    bad.mkdir()
    shutil.copy(shipped_folder() / "manifest.json", bad / "manifest.json")
    manifest = json.loads((bad / "manifest.json").read_text())
    f = manifest["concepts"]["swap_locations"]["file"]
    data = bytearray((shipped_folder() / f).read_bytes())
    data[len(data) // 2] ^= 0xFF
    (bad / f).write_bytes(bytes(data))
    notjson = tmp_path / "notjson"
    notjson.mkdir()
    (notjson / "manifest.json").write_text("{")
    far = tmp_path / "far.json"
    far.write_text(json.dumps({"objects": [{"shape": "star", "color": "red", "x": 1.5, "y": 0.4, "width": 0.1}]}))
    cases = [
        (["run", "scene_parse", "--scene", str(far)], f"{far}: object 0 (red star"),
        (["run", "scene_parse", "--image", str(tmp_path)], f"{tmp_path}: not an image file"),
        (["run", str(tmp_path)], f"{tmp_path}: a folder, not a program"),
        (["run", "--concept", "swap_locations", "--image", str(tmp_path / "none.png")], "none.png: no such image file"),
        (["run", "--concept", "swap_locations", "--image", str(junk)], "not an image OpenCV can read"),
        (["run", "--concept", "swap_locations", "--image", str(blank)], "blank.png: no objects found in the image"),
        (["run", "scene_parse", "--example", "0"], "--example K takes the K-th example pair of --concept"),
        (["run", "--concept", "swap_locations", "--example", "10"], "has 10 train pairs (0 to 9)"),
        (["run", "--concept", "swap_locations", "--example", "0", "--scene", "s.json"], "not several"),
        (["run", "--concept", "swap_locations", "--example", "0", "--dataset", str(bad)], f"{f}: sha256 differs"),
        (["run", "--concept", "swap_locations", "--example", "0", "--dataset", str(notjson)], "manifest.json"),
        (["dataset", "info", str(bad)], "c000.npz: missing"),
        (["trace", "--concept", "swap_locations", "--out", "t.jpg"], "t.jpg: write .png or .gif"),
        (["trace", "scene_parse; fixate(up)", "--out", "t.png"], "argument must be one of"),
        (["trace", "--concept", "no_such_concept", "--out", "t.png"], "unknown concept 'no_such_concept'"),
    ]
    for argv, message in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.startswith("vcc") and ": error: " in err and message in err and err.count("\n") == 1, (argv, err)


def test_perception_eval_reports_json(capsys):
    assert main(["perception", "eval", "--images", "3", "--styles", "schematic", "--size", "256"]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    report = json.loads(line)
    assert report["images"] == 3 and 0 <= report["recovered"] <= 1


def test_a_bug_is_one_line_naming_where_its_traceback_was_saved(capsys, monkeypatch, tmp_path):
    import argparse

    from vccjax import runtime

    monkeypatch.setenv("HOME", str(tmp_path))

    def broken(a):
        raise RuntimeError("something impossible")

    parser = runtime.Parser(prog="vcc")
    parser.set_defaults(fn=broken)
    assert runtime.run_command(parser, []) == 70
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error (a bug" in err and "RuntimeError: something impossible" in err
    saved = Path(err.rsplit("traceback saved to ", 1)[1].strip())
    assert saved.is_file() and "Traceback" in saved.read_text() and "something impossible" in saved.read_text()
    assert isinstance(parser, argparse.ArgumentParser)


def test_ctrl_c_is_one_line_and_exit_130(capsys):
    from vccjax import runtime

    def interrupted(a):
        raise KeyboardInterrupt

    parser = runtime.Parser(prog="vcc")
    parser.set_defaults(fn=interrupted)
    assert runtime.run_command(parser, []) == 130
    assert capsys.readouterr().err == "vcc: interrupted; rerun the same command to resume\n"


def test_ctrl_c_inside_a_gc_callback_is_sent_again_not_lost(monkeypatch):
    """Python drops an exception raised in a garbage-collector callback: Ctrl-C arriving
    there is sent again a moment later; anywhere else it interrupts at once."""
    import gc
    import signal
    import sys

    import pytest

    from vccjax import runtime

    sent, seen = [], []
    monkeypatch.setattr(runtime, "send_again", lambda: sent.append(True))

    def callback(phase, info):
        try:
            runtime.on_interrupt(signal.SIGINT, sys._getframe())
            seen.append("deferred")
        except KeyboardInterrupt:
            seen.append("raised")

    gc.callbacks.append(callback)
    try:
        gc.collect()
    finally:
        gc.callbacks.remove(callback)
    assert seen and set(seen) == {"deferred"} and len(sent) == len(seen)
    with pytest.raises(KeyboardInterrupt):
        runtime.on_interrupt(signal.SIGINT, sys._getframe())


def test_a_command_takes_ctrl_c_by_its_handler_and_gives_the_old_one_back():
    import signal

    from vccjax import runtime

    def command(a):
        assert signal.getsignal(signal.SIGINT) is runtime.on_interrupt
        return 0

    before = signal.getsignal(signal.SIGINT)
    parser = runtime.Parser(prog="vcc")
    parser.set_defaults(fn=command)
    assert runtime.run_command(parser, []) == 0
    assert signal.getsignal(signal.SIGINT) is before


def test_a_reader_that_goes_away_ends_the_command_quietly(capsys):
    """`vcc concepts | head`: the pipe's reader closes early; that is no error (a
    BrokenPipeError is an OSError, which bad input also raises)."""
    from vccjax import runtime

    def piped(a):
        raise BrokenPipeError(32, "Broken pipe")

    parser = runtime.Parser(prog="vcc")
    parser.set_defaults(fn=piped)
    assert runtime.run_command(parser, []) == 0
    assert capsys.readouterr().err == ""


def test_an_option_given_twice_is_refused_in_one_line(capsys):
    assert main(["run", "scene_parse", "--seed", "1", "--seed", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--seed given twice" in err
