"""The learned library: built from a run folder it holds the model explore-compress
would fit on that run's programs; the shipped file is what `vcc library build` makes
from the run of record; edited, foreign and other-version files are refused."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from search import library
from search.induce import Settings, fit_model
from vcc.cli import main
from vccjax.errors import DataFileError
from vccjax.sealed import seal
from vccjax.machine.program import parse
from vccjax.world.concepts import concept_names, reference_program

RUN_OF_RECORD = Path(__file__).parents[2] / "benchmarks" / "induction" / "o1-oracle-500k"
FEW = concept_names()[:40]


@pytest.fixture()
def run_folder(tmp_path):
    """A small finished run: forty concepts found (their reference programs), one not."""
    settings = {"budget": 1000, "order": 1, "args": "oracle", "subroutines": True, "epsilon": 0.1,
                "max_iterations": 8, "max_subroutines": 100, "delta": 0.01}
    (tmp_path / "run.json").write_text(json.dumps({"format": "vccjax-induce", "version": 1, "settings": settings}))
    lines = [{"concept": c, "found": True, "iteration": 0, "program": reference_program(c).text()} for c in FEW]
    lines.append({"concept": concept_names()[40], "found": False, "iteration": 0, "program": None})
    (tmp_path / "results.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))
    return tmp_path


def test_a_library_holds_the_model_fitted_on_the_runs_programs(run_folder, tmp_path):
    path = tmp_path / "lib.json"
    library.save(library.build(run_folder), path)
    lib = library.load(path)
    vocab, model = fit_model([parse(reference_program(c).text()) for c in sorted(FEW)], Settings(), True)
    assert lib.vocab == vocab and lib.vocab.bodies  # forty programs share parts: subroutines
    np.testing.assert_array_equal(lib.model.logp, model.logp)
    assert lib.card["concepts"] == sorted(FEW) and lib.card["source_run"] == run_folder.name


@pytest.mark.parametrize("edit, message", [
    (lambda c: c["transitions"][0].__setitem__(2, c["transitions"][0][2] + 1), "content sha256 mismatch"),
    (lambda c: c.__setitem__("subroutines", c["subroutines"][:-1]), "content sha256 mismatch"),
    (lambda c: c.__setitem__("format", "something-else"), "not a vccjax-library file"),
])
def test_an_edited_or_foreign_library_is_refused(run_folder, tmp_path, edit, message):
    content = library.build(run_folder)
    edit(content)
    path = tmp_path / "lib.json"
    path.write_text(json.dumps(content))
    with pytest.raises(DataFileError, match=message):
        library.load(path)


def test_a_library_of_another_version_or_predictor_is_refused(run_folder, tmp_path):
    path = tmp_path / "lib.json"
    for field, value, message in (("version", library.VERSION + 1, "format version"),
                                  ("card", None, "other argument-predictor weights")):
        content = library.build(run_folder)
        if field == "card":
            content["card"]["predictor_sha256"] = "0" * 64
        else:
            content[field] = value
        library.save(seal(content), path)  # sealed again: only the check itself can refuse
        with pytest.raises(DataFileError, match=message):
            library.load(path)
    path.write_text("{not json")
    with pytest.raises(DataFileError, match="lib.json: not JSON"):
        library.load(path)


def test_the_shipped_library_is_what_build_makes_from_the_run_of_record(tmp_path, capsys):
    out = tmp_path / "library.json"
    assert main(["library", "build", "--from", str(RUN_OF_RECORD), "--out", str(out)]) == 0
    assert out.read_bytes() == library.shipped_library().read_bytes()
    lib = library.load()
    found = {json.loads(x)["concept"] for x in (RUN_OF_RECORD / "results.jsonl").read_text().splitlines()
             if json.loads(x)["found"]}
    assert lib.card["concepts"] == sorted(found)
    assert main(["library", "show"]) == 0 and lib.sha256 in capsys.readouterr().out


def test_library_build_refuses_a_folder_that_is_not_a_run(tmp_path, capsys):
    assert main(["library", "build", "--from", str(tmp_path), "--out", str(tmp_path / "x.json")]) == 2
    assert "run.json: missing" in capsys.readouterr().err and not (tmp_path / "x.json").exists()
