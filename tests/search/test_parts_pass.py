"""Explore-compress's pass over the concepts it missed, learned in parts
(`search.parts_pass`): what it adds, that a finished run resumed gains it without
redoing anything, and what a resume still refuses."""

from __future__ import annotations

import json

import pytest

from search.induce import Settings, induce, read_records
from search.run_summary import summary
from search.scalar import ScalarExplorer
from vcc.cli import main
from vccjax.errors import DataFileError
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.program import parse
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import scenes_match
from vccjax.world.dataset import Dataset

TWO_PARTS = ("scene_parse; fixate(top); top_down_attend; fill_color(red); reset_attn; "
             "fixate(bottom); top_down_attend; fill_color(blue)")
PROGRAMS = f"""# a two-part concept whose whole program lies past a small budget, and two short ones
recolor_top_red_and_bottom_blue: {TWO_PARTS}
recolor_bottom_obj_blue: scene_parse; fixate(bottom); top_down_attend; fill_color(blue)
recolor_top_obj_red: scene_parse; fixate(top); top_down_attend; fill_color(red)
"""
BUDGET = 20_000


@pytest.fixture(scope="module")
def ds(tmp_path_factory):
    root = tmp_path_factory.mktemp("parts_pass")
    (root / "programs.txt").write_text(PROGRAMS)
    assert main(["dataset", "build", "--programs", str(root / "programs.txt"), "--out", str(root / "ds"),
                 "--workers", "1"]) == 0
    return Dataset(root / "ds")


def _induce(ds, out, parts: int, concepts=("recolor_top_red_and_bottom_blue", "recolor_bottom_obj_blue"), **kw):
    return induce(list(concepts), ds.pairs, out, Settings(**{"budget": BUDGET, "args": "oracle", "max_iterations": 1,
                                                          "parts": parts, **kw}),
                  explorer=ScalarExplorer(width=1), progress=False, answers=ds.program, log=lambda _: None)


def test_a_finished_run_resumed_with_parts_learns_what_it_missed(ds, tmp_path):
    out = tmp_path / "run"
    run = _induce(ds, out, parts=1)
    assert set(run.found()) == {"recolor_bottom_obj_blue"}  # the whole two-part program: past the budget
    before = (out / "results.jsonl").read_text()

    run = _induce(ds, out, parts=2)
    assert (out / "results.jsonl").read_text().startswith(before)  # nothing redone, nothing rewritten
    rec = run.found()["recolor_top_red_and_bottom_blue"]
    assert rec["parts"] == 2 and rec["iteration"] == 1  # the pass's number: past every iteration's
    program = parse(rec["program"])
    for a, b in ds.pairs("recolor_top_red_and_bottom_blue", "train"):  # checked like any found program
        m = RefMachine(a).run(program)
        assert not m.failed and scenes_match(m.output_scene(), b, DEFAULT_CONFIG.tau)
    assert rec["test_correct"] == rec["test_total"] == len(ds.pairs("recolor_top_red_and_bottom_blue", "test"))
    s = summary(run, list(run.found()))
    assert s["found"] == 2 and s["found_in_parts"] == s["found_in_last_pass"] == 1
    assert s["per_iteration"] == {0: 1, 1: 1}
    assert (out / "model-1.json").exists()  # the model the pass searched with
    assert json.loads((out / "run.json").read_text())["settings"]["parts"] == 2

    lines, model = len(read_records(out / "results.jsonl")), (out / "model-1.json").read_text()
    _induce(ds, out, parts=2)  # resumed again: the pass is not repeated
    assert len(read_records(out / "results.jsonl")) == lines
    # and its model is the one it searched with: fitted on the iterations' programs, not
    # on what the pass itself found (a refit would add the two-part program)
    assert (out / "model-1.json").read_text() == model


def test_the_last_pass_searches_whole_first_with_the_model_of_what_was_found(ds, tmp_path):
    """A concept the iterations missed that the model fitted on everything found ranks
    within the budget is found whole (no parts) by the pass, as one more iteration would.
    The run is made to have missed it: its iteration-0 record says so."""
    out = tmp_path / "run"
    _induce(ds, out, parts=1, concepts=["recolor_bottom_obj_blue"])
    from vccjax.records import append_line

    append_line(out / "results.jsonl", {"concept": "recolor_top_obj_red", "found": False, "iteration": 0,
                                        "program": None, "dl": None, "covered": BUDGET, "seconds": 0.0,
                                        "nodes": 0, "programs_run": 0, "test_correct": None, "test_total": None})
    run = _induce(ds, out, parts=2, concepts=["recolor_bottom_obj_blue", "recolor_top_obj_red"])
    rec = run.found()["recolor_top_obj_red"]
    assert rec["last_pass"] and rec["parts"] == 0 and rec["iteration"] == 1
    assert rec["program"] == "scene_parse; fixate(top); top_down_attend; fill_color(red)"
    assert rec["rank"] <= BUDGET and rec["covered"] == rec["rank"]


def test_a_resume_with_other_search_settings_is_still_refused(ds, tmp_path):
    out = tmp_path / "run"
    _induce(ds, out, parts=1)
    with pytest.raises(DataFileError, match="other settings"):
        _induce(ds, out, parts=2, epsilon=0.2)


def test_a_run_recorded_before_the_argument_threshold_resumes_at_055_only(ds, tmp_path):
    """run.json written before `arg_threshold` existed searched at the paper's 0.55: it
    resumes with 0.55 and refuses another threshold (which would search otherwise)."""
    out = tmp_path / "run"
    _induce(ds, out, parts=1)
    meta = json.loads((out / "run.json").read_text())
    assert meta["settings"].pop("arg_threshold") == 0.55
    (out / "run.json").write_text(json.dumps(meta))
    _induce(ds, out, parts=1)  # resumed: nothing to redo
    with pytest.raises(DataFileError, match="other settings"):
        _induce(ds, out, parts=1, arg_threshold=0.6)


@pytest.mark.parametrize("option,value", [("--arg-threshold", "0"), ("--arg-threshold", "1.5"),
                                          ("--arg-threshold", "high")])
def test_a_bad_argument_threshold_is_one_line(tmp_path, capsys, option, value):
    assert main(["induce", "--concepts", "demo", "--out", str(tmp_path / "r"), option, value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and option in err[0]
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("value", ["0", "4", "two"])
def test_a_bad_parts_value_is_one_line(tmp_path, capsys, value):
    assert main(["induce", "--concepts", "demo", "--out", str(tmp_path / "r"), "--parts", value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--parts" in err[0]
    assert not (tmp_path / "r").exists()


def test_a_run_recorded_before_fill_took_the_networks_fill_arguments_and_resumes_so_only(ds, tmp_path):
    """run.json written before `fill` existed took fill_color's arguments from the network:
    with predicted arguments it resumes with `fill="predicted"` only; the setting means
    nothing to oracle arguments, so there any resumes."""
    from search.induce import same_search

    out = tmp_path / "run"
    _induce(ds, out, parts=1, args="predicted", fill="predicted", concepts=["recolor_bottom_obj_blue"])
    meta = json.loads((out / "run.json").read_text())
    assert meta["settings"].pop("fill") == "predicted"
    (out / "run.json").write_text(json.dumps(meta))
    _induce(ds, out, parts=1, args="predicted", fill="predicted", concepts=["recolor_bottom_obj_blue"])
    with pytest.raises(DataFileError, match="other settings"):
        _induce(ds, out, parts=1, args="predicted", concepts=["recolor_bottom_obj_blue"])  # fill gained
    old_oracle = {k: v for k, v in Settings(args="oracle").__dict__.items() if k != "fill"}
    assert same_search(old_oracle, Settings(args="oracle", fill="gained").__dict__)
    assert not same_search({**old_oracle, "args": "predicted"}, Settings(args="predicted").__dict__)


def test_a_run_recorded_before_filters_searched_the_networks_filters_and_resumes_so_only(ds, tmp_path):
    """run.json written before `filters` existed searched with the network's filters alone:
    with predicted arguments it resumes with `filters="network"` only; oracle arguments
    take no filter from the network, so there any resumes."""
    from search.induce import same_search

    out = tmp_path / "run"
    one = ["recolor_bottom_obj_blue"]
    _induce(ds, out, parts=1, args="predicted", filters="network", concepts=one)
    meta = json.loads((out / "run.json").read_text())
    assert meta["settings"].pop("filters") == "network"
    (out / "run.json").write_text(json.dumps(meta))
    _induce(ds, out, parts=1, args="predicted", filters="network", concepts=one)
    with pytest.raises(DataFileError, match="other settings"):
        _induce(ds, out, parts=1, args="predicted", concepts=one)  # filters acted
    old_oracle = {k: v for k, v in Settings(args="oracle").__dict__.items() if k != "filters"}
    assert same_search(old_oracle, Settings(args="oracle", filters="acted").__dict__)
    assert not same_search({**old_oracle, "args": "predicted"}, Settings(args="predicted").__dict__)
    with pytest.raises(ValueError, match="--filters must be one of"):
        Settings(filters="both")


@pytest.mark.parametrize("option,value", [("--fill", "both"), ("--fill", ""), ("--filters", "both"),
                                          ("--filters", "")])
def test_a_bad_fill_is_one_line(tmp_path, capsys, option, value):
    assert main(["induce", "--concepts", "demo", "--out", str(tmp_path / "r"), option, value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and option in err[0]
    assert not (tmp_path / "r").exists()
