"""Induction on a dataset of the user's own concepts: `vcc dataset build --programs`,
`vcc induce --dataset` over its manifest, oracle arguments read from the programs stored
with the examples, a run started from the shipped library, and the errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from search.induce import Settings, argument_logp
from vcc.cli import main
from vccjax.world.dataset import Dataset, stream_key
from vccjax.world.concepts import concept_names

PROGRAMS = """# two concepts that are not among the 546
recolor_bottom_obj_blue: scene_parse; fixate(bottom); top_down_attend; fill_color(blue)
remove_obj_nearest_left_edge: scene_parse; fixate(left); top_down_attend; remove_from_imagine_buffer
"""


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    root = tmp_path_factory.mktemp("own")
    (root / "programs.txt").write_text(PROGRAMS)
    assert main(["dataset", "build", "--programs", str(root / "programs.txt"), "--out", str(root / "ds"),
                 "--workers", "1"]) == 0
    return root


def test_examples_are_made_from_the_given_programs(built):
    ds = Dataset(built / "ds")
    assert ds.concepts == ["recolor_bottom_obj_blue", "remove_obj_nearest_left_edge"]
    from vccjax.machine.reference import RefMachine
    from vccjax.machine.scene import scenes_match

    for c in ds.concepts:
        program = ds.program(c)
        assert program.text() in PROGRAMS
        for a, b in ds.pairs(c, "train") + ds.pairs(c, "test"):
            m = RefMachine(a).run(program)
            assert not m.failed and scenes_match(m.output_scene(), b, 0.0234375)


def test_a_concepts_stream_comes_from_its_name():
    assert stream_key(concept_names()[7]) == 7  # the 546 keep their examples byte for byte
    a, b = stream_key("recolor_bottom_obj_blue"), stream_key("remove_obj_nearest_left_edge")
    assert a != b and a >= 546 and a == stream_key("recolor_bottom_obj_blue")


def test_induce_takes_the_datasets_concepts_and_their_stored_programs(built, capsys, monkeypatch):
    monkeypatch.setenv("VCCJAX_CACHE", "off")
    out = built / "run"
    assert main(["induce", "--dataset", str(built / "ds"), "--out", str(out), "--budget", "20000",
                 "--iterations", "1", "--args", "oracle", "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["concepts"] == 2 and summary["found"] == 2
    ds = Dataset(built / "ds")
    lp = argument_logp(Settings(args="oracle"), "recolor_bottom_obj_blue", answer=ds.program("recolor_bottom_obj_blue"))
    from vccjax.machine.instructions import OP

    assert np.isfinite(lp[OP["fill_color"]]).sum() == 1  # blue only: read from the stored program


def test_induce_from_the_library_makes_one_pass(built, capsys, monkeypatch):
    monkeypatch.setenv("VCCJAX_CACHE", "off")
    out = built / "lib-run"
    argv = ["induce", "--dataset", str(built / "ds"), "--out", str(out), "--budget", "20000", "--model", "library",
            "--quiet"]
    assert main(argv) == 0
    records = [json.loads(x) for x in (out / "results.jsonl").read_text().splitlines()]
    assert {r["iteration"] for r in records} == {0} and all(r["found"] for r in records)
    meta = json.loads((out / "run.json").read_text())
    assert meta["start_model"] != "uniform"
    capsys.readouterr()
    assert main(["induce", "--dataset", str(built / "ds"), "--out", str(out), "--budget", "20000", "--quiet"]) == 2
    assert "started from model" in capsys.readouterr().err


@pytest.mark.parametrize("text, message", [
    ("just words\n", ":1: expected `name: program`"),
    ("a_b: scene_parse\na_b: scene_parse\n", ":2: 'a_b' is given twice"),
    ("remove_bottom_obj: scene_parse\n", "one of the 546 shipped concepts"),
    ("x: scene_parse; no_such_instruction\n", ":1:"),
    ("# only a comment\n", "holds no `name: program` line"),
])
def test_a_bad_programs_file_is_refused_by_line(tmp_path, capsys, text, message):
    (tmp_path / "p.txt").write_text(text)
    assert main(["dataset", "build", "--programs", str(tmp_path / "p.txt"), "--out", str(tmp_path / "ds")]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "ds").exists()


def test_induce_refuses_a_concept_outside_the_dataset_and_a_foreign_model(built, tmp_path, capsys):
    assert main(["induce", "--dataset", str(built / "ds"), "--concepts", "remove_bottom_obj",
                 "--out", str(tmp_path / "r")]) == 2
    assert "not in the dataset's manifest" in capsys.readouterr().err
    (tmp_path / "m.json").write_text(json.dumps({"logp": [[0.0]], "order": 1, "subroutines": []}))
    assert main(["induce", "--dataset", str(built / "ds"), "--model", str(tmp_path / "m.json"),
                 "--out", str(tmp_path / "r")]) == 2
    assert "transition table of shape" in capsys.readouterr().err


def test_an_instruction_no_training_pair_needs_is_warned_of(tmp_path, capsys):
    # Without reset_attn, the second top_down_attend refreshes a fresh attended list and
    # keeps the top object (docs/vcc.md, "Refreshing A"): fill_color(blue) overwrites the
    # red, so the program's first fill_color changes no example.
    (tmp_path / "p.txt").write_text("recolor_top_red_and_bottom_blue: scene_parse; fixate(top); top_down_attend; "
                                    "fill_color(red); fixate(bottom); top_down_attend; fill_color(blue)\n")
    assert main(["dataset", "build", "--programs", str(tmp_path / "p.txt"), "--out", str(tmp_path / "ds"),
                 "--workers", "1"]) == 0
    out = capsys.readouterr().out
    assert "warning: recolor_top_red_and_bottom_blue" in out and "without fill_color at 3" in out
