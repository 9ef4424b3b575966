"""The `vcc` command: demo output, and one-line errors (exit code 2) for user mistakes."""

from __future__ import annotations

import json

from vcc.cli import main


def test_run_concept_prints_before_and_after(capsys):
    assert main(["run", "--concept", "move_to_middle", "--engine", "reference"]) == 0
    out = capsys.readouterr().out
    assert "before" in out and "after" in out and out.strip().endswith("changed")


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
    cases = [
        (["run", "--concept", "swap_locations", "--image", str(tmp_path / "none.png")], "none.png: no such image file"),
        (["run", "--concept", "swap_locations", "--image", str(junk)], "not an image OpenCV can read"),
        (["run", "--concept", "swap_locations", "--image", str(blank)], "blank.png: no objects found in the image"),
        (["run", "scene_parse", "--example", "0"], "--example K takes the K-th example pair of --concept"),
        (["run", "--concept", "swap_locations", "--example", "10"], "has 10 train pairs (0 to 9)"),
        (["run", "--concept", "swap_locations", "--example", "0", "--scene", "s.json"], "not several"),
        (["run", "--concept", "swap_locations", "--example", "0", "--dataset", str(bad)], f"{f}: sha256 differs"),
        (["run", "--concept", "swap_locations", "--example", "0", "--dataset", str(notjson)], "manifest.json"),
        (["dataset", "info", str(bad)], "c000.npz: missing"),
        (["trace", "--concept", "swap_locations", "--out", "t.jpg"], "write a .png sheet or a .gif animation"),
        (["trace", "scene_parse; fixate(up)", "--out", "t.png"], "argument must be one of"),
        (["trace", "--concept", "no_such_concept", "--out", "t.png"], "unknown concept 'no_such_concept'"),
    ]
    for argv, message in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.startswith("vcc: error: ") and message in err and err.count("\n") == 1, (argv, err)


def test_perception_eval_reports_json(capsys):
    assert main(["perception", "eval", "--images", "3", "--styles", "schematic", "--size", "256"]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    report = json.loads(line)
    assert report["images"] == 3 and 0 <= report["recovered"] <= 1
