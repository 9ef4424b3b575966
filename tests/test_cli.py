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


def test_perception_eval_reports_json(capsys):
    assert main(["perception", "eval", "--images", "3", "--styles", "schematic", "--size", "256"]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    report = json.loads(line)
    assert report["images"] == 3 and 0 <= report["recovered"] <= 1
