"""Induction: the batched search agrees with the scalar-driven one, finds short concepts,
persists after every concept and resumes without losing or redoing anything."""

from __future__ import annotations

import json

import pytest

from search.chain import Chain, uniform_args
from search.explore import Explorer, Task
from search.induce import Run, Settings, argument_logp, induce
from search.model import MarkovModel, Vocabulary
from search.scalar import ScalarExplorer
from vcc.cli import main
from vccjax.world.concepts import reference_program
from vccjax.world.dataset import Dataset, build_dataset
from vccjax.errors import DataFileError

SHORT = ["remove_bottom_obj", "change_target_obj_to_given_color", "remove_left_most_obj"]
LONG = "swap_locations"
LOOP = "change_all_objs_color"


@pytest.fixture(scope="module")
def ds(tmp_path_factory):
    out = tmp_path_factory.mktemp("ds")
    build_dataset(out, [*SHORT, LONG, LOOP], seed=0, progress=False)
    return Dataset(out)


@pytest.fixture(scope="module")
def explorer():
    return Explorer()


def _uniform_chain():
    v = Vocabulary()
    return Chain(v, MarkovModel.uniform(v.size), uniform_args())


def _loop_chain():
    """A model that likes loops (fitted on the reference programs: only to make loops
    likely here) so that `loop_end` and its replay (`stepping.replay_loops`) are exercised."""
    from vccjax.world.concepts import all_concepts

    v = Vocabulary()
    model = MarkovModel.fit([list(p.ops) for p in all_concepts().values()], v.size, 1, 0.1)
    return Chain(v, model, argument_logp(Settings(args="oracle"), LOOP))


@pytest.mark.parametrize("concept", ["remove_bottom_obj", LONG])
def test_batched_and_scalar_search_visit_the_same_tree(ds, explorer, concept):
    task = Task.from_pairs(ds.pairs(concept, "train"))
    chain = _uniform_chain()
    a = explorer.search(chain, task, 20_000)
    b = ScalarExplorer().search(chain, task, 20_000)
    assert (a.found, a.text, a.rank, a.dl_bins) == (b.found, b.text, b.rank, b.dl_bins)
    assert (a.nodes, a.programs) == (b.nodes, b.programs)
    assert a.programs <= 20_000


def test_loops_replayed_on_the_device_agree_with_the_scalar_search(ds, explorer):
    """Loops under a model that likes them (`_loop_chain`)."""
    chain = _loop_chain()
    task = Task.from_pairs(ds.pairs(LOOP, "train"))
    a = explorer.search(chain, task, 3000)
    b = ScalarExplorer().search(chain, task, 3000)
    assert a.found and "loop_end" in a.text
    assert (a.text, a.rank, a.nodes, a.programs) == (b.text, b.rank, b.nodes, b.programs)


def test_concepts_explored_together_find_what_each_finds_alone(ds):
    """search_many steps several concepts' prefixes in one batch (here 3 bank slots for
    5 concepts, so slots are reused); each concept's search must be unchanged."""
    explorer = Explorer(width=3)
    names = [*SHORT, LONG, LOOP]
    jobs = [(Chain(Vocabulary(), MarkovModel.uniform(Vocabulary().size), argument_logp(Settings(args="oracle"), c)),
             Task.from_pairs(ds.pairs(c, "train"))) for c in names]
    together: dict[int, object] = {}
    explorer.search_many(jobs, 20_000, together.__setitem__)
    assert sorted(together) == list(range(len(names)))
    for j, (chain, task) in enumerate(jobs):
        alone = explorer.search(chain, task, 20_000)
        t = together[j]
        assert (t.found, t.text, t.rank, t.nodes, t.programs) == (alone.found, alone.text, alone.rank, alone.nodes,
                                                                  alone.programs), names[j]
    assert sum(together[j].found for j in range(len(names))) >= 3


_TWO_DEVICES = """  # _loop_chain's search, in a process with two devices
import json, sys
folder, concept, here = sys.argv[1:]
sys.path.insert(0, here)
from test_induce import _loop_chain
from search.explore import Explorer, Task
from vccjax.world.dataset import Dataset

ex = Explorer()
r = ex.search(_loop_chain(), Task.from_pairs(Dataset(folder).pairs(concept, "train")), 3000)
print(json.dumps({"devices": len(ex.devices), "rows_run": ex.backend.calls.rows_run,
                  "result": [r.text, r.rank, r.nodes, r.programs]}))
"""


def test_batches_split_over_two_devices_give_the_same_search(ds, explorer):
    """A batch's pieces are dealt out to the JAX devices; with two (forced host devices,
    in a fresh process) both run pieces and the search is the one a single device makes."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, XLA_FLAGS="--xla_force_host_platform_device_count=2")
    out = subprocess.run([sys.executable, "-c", _TWO_DEVICES, str(ds.folder), LOOP, os.path.dirname(__file__)], env=env,
                         capture_output=True, text=True, timeout=1200)
    assert out.returncode == 0, out.stderr[-2000:]
    two = json.loads(out.stdout.strip().splitlines()[-1])
    assert two["devices"] == 2 and min(two["rows_run"]) > 0
    one = explorer.search(_loop_chain(), Task.from_pairs(ds.pairs(LOOP, "train")), 3000)
    assert len(explorer.devices) == 1
    assert two["result"] == [one.text, one.rank, one.nodes, one.programs]


def test_brute_force_finds_the_reference_program_of_a_short_concept(ds, explorer):
    task = Task.from_pairs(ds.pairs("remove_bottom_obj", "train"))
    r = explorer.search(_uniform_chain(), task, 30_000)
    assert r.found and r.program == reference_program("remove_bottom_obj")
    assert 1 <= r.rank <= 30_000
    # too small a budget: the program lies beyond it, so nothing is found
    small = explorer.search(_uniform_chain(), task, r.rank - 1)
    assert not small.found and small.programs <= r.rank - 1


def test_oracle_arguments_exclude_unused_instructions():
    lp = argument_logp(Settings(args="oracle"), "remove_bottom_obj")  # uses fixate(bottom) only
    from vccjax.machine.instructions import OP

    assert (lp[OP["fixate"]] == 0).sum() == 1
    assert all(v == float("-inf") for v in lp[OP["set_color_attn"]])
    with pytest.raises(ValueError, match="training pairs"):
        argument_logp(Settings(args="predicted"), "remove_bottom_obj")


class CountingExplorer(Explorer):
    def __init__(self, fail_after: int | None = None):
        super().__init__()
        self.calls: list[int] = []
        self.fail_after = fail_after

    def search_many(self, jobs, budget, done):
        def counted(j, r):
            if self.fail_after is not None and len(self.calls) >= self.fail_after:
                raise KeyboardInterrupt  # as if the user pressed Ctrl-C here
            self.calls.append(j)
            done(j, r)

        super().search_many(jobs, budget, counted)


def test_interrupted_run_resumes_without_losing_or_redoing(ds, tmp_path):
    settings = Settings(budget=3000, args="oracle", max_iterations=2)
    out = tmp_path / "run"
    with pytest.raises(KeyboardInterrupt):
        induce(SHORT, ds.pairs, out, settings, explorer=CountingExplorer(fail_after=2), progress=False,
               examples_sha256=ds.sha256)
    first = [json.loads(x) for x in (out / "results.jsonl").read_text().splitlines()]
    assert len(first) == 2 and {r["concept"] for r in first} < set(SHORT) and all(r["found"] for r in first)
    # a line half written when the process died is dropped and its concept redone
    with (out / "results.jsonl").open("a") as f:
        f.write('{"concept": "remove_left_most_obj", "fou')
    again = CountingExplorer()
    run = induce(SHORT, ds.pairs, out, settings, explorer=again, progress=False, examples_sha256=ds.sha256)
    assert len(again.calls) == 1  # only the concept not yet done
    found = run.found()
    assert set(found) == set(SHORT)
    assert [found[r["concept"]]["program"] for r in first] == [r["program"] for r in first]
    for r in found.values():
        assert r["test_correct"] == r["test_total"] == 50
        assert {"concept", "found", "program", "dl", "nodes", "rank", "seconds", "iteration"} <= set(r)
    # the same folder with other settings is refused, not mixed
    with pytest.raises(DataFileError, match="other settings"):
        Run(out, Settings(budget=4000, args="oracle", max_iterations=2))
    # ... and so are other examples (a rebuilt dataset), before anything is searched or
    # written: run.json stays as it was (no session recorded for the refused resume)
    other, meta = CountingExplorer(), (out / "run.json").read_bytes()
    with pytest.raises(DataFileError, match="other examples for remove_"):
        induce(SHORT, ds.pairs, out, settings, explorer=other, progress=False,
               examples_sha256=lambda c: "0" * 64 if c == SHORT[0] else ds.sha256(c))
    assert other.calls == [] and len((out / "results.jsonl").read_text().splitlines()) == len(run.records)
    assert (out / "run.json").read_bytes() == meta


def test_cli_induce_runs_and_reports(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("VCCJAX_CACHE", "off")
    out = tmp_path / "cli"
    argv = ["induce", "--concepts", "remove_bottom_obj,remove_top_obj", "--out", str(out),
            "--budget", "2000", "--iterations", "1", "--args", "oracle", "--quiet"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "induced" in text and "programs/s" in text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["found"] == 2 and summary["exact_on_all_test_pairs"] == 2
    assert summary["found_without_subroutines"] == 2  # iteration 0 has none
    assert 0 < summary["search_seconds"] + summary["compile_seconds"] <= summary["wall_seconds"] + 1
    # rerun: everything is already there, nothing is searched again
    assert main(argv) == 0
    lines = (out / "results.jsonl").read_text().splitlines()
    assert len(lines) == 2
    meta = json.loads((out / "run.json").read_text())  # the rerun had nothing to do: no session of its own
    assert len(meta["sessions"]) == 1 and set(meta["examples_sha256"]) == {"remove_bottom_obj", "remove_top_obj"}


@pytest.mark.parametrize("argv, msg", [
    (["induce", "--concepts", "no_such_concept", "--out", "X"], "unknown concept"),
    (["induce", "--concepts", "remove_top_obj", "--out", "X", "--budget", "0"], "budget"),
])
def test_cli_induce_errors_are_one_line(tmp_path, capsys, argv, msg, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert msg in err and len(err.splitlines()) == 1


def test_cli_induce_refuses_a_dataset_without_the_concept_or_other_examples(tmp_path, capsys, monkeypatch):
    import shutil

    from vccjax.world.dataset import shipped_folder

    monkeypatch.setenv("VCCJAX_CACHE", "off")
    part = tmp_path / "part"
    part.mkdir()
    manifest = json.loads((shipped_folder() / "manifest.json").read_text())
    entry = manifest["concepts"]["remove_bottom_obj"]
    shutil.copy(shipped_folder() / entry["file"], part / entry["file"])
    (part / "manifest.json").write_text(json.dumps({**manifest, "concepts": {"remove_bottom_obj": entry}}))
    argv = ["induce", "--concepts", "remove_top_obj", "--out", str(tmp_path / "run"), "--dataset", str(part)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "unknown concept(s): remove_top_obj (not in the dataset's manifest)" in err and len(err.splitlines()) == 1
    # a run started on the shipped examples does not resume on other ones
    run = ["induce", "--concepts", "remove_bottom_obj", "--out", str(tmp_path / "run"), "--budget", "500",
           "--iterations", "1", "--quiet"]
    assert main(run) == 0
    capsys.readouterr()
    import hashlib

    from vccjax.world.dataset import read_npz, write_npz

    arrays = read_npz(part / entry["file"])  # rebuilt differently: one test scene moved a little
    arrays["test_in"][0, 0, 3] = min(arrays["test_in"][0, 0, 3] + 0.001, 0.9)
    write_npz(part / entry["file"], arrays)
    entry["sha256"] = hashlib.sha256((part / entry["file"]).read_bytes()).hexdigest()
    (part / "manifest.json").write_text(json.dumps({**manifest, "concepts": {"remove_bottom_obj": entry}}))
    assert main([*run, "--dataset", str(part)]) == 2
    err = capsys.readouterr().err.strip()
    assert "other examples for remove_bottom_obj" in err and len(err.splitlines()) == 1


def test_cli_induces_a_dozen_short_concepts_end_to_end(tmp_path, capsys):
    """The CI-sized run: examples built, explore-compress over a dozen concepts, every
    found program checked on its 50 test pairs, the summary table printed."""
    out = tmp_path / "dozen"
    argv = ["induce", "--concepts", "demo", "--out", str(out), "--budget", "20000",
            "--iterations", "3", "--quiet"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert summary["concepts"] == 12
    assert summary["found"] >= 10, summary
    assert summary["exact_on_all_test_pairs"] >= summary["found"] - 1, summary
    assert f"{'induced':<28}{summary['found']}" in text and "throughput" in text
    records = [json.loads(x) for x in (out / "results.jsonl").read_text().splitlines()]
    assert all(r["covered"] <= 20000 for r in records)


def test_a_run_with_predicted_arguments_resumes_only_under_the_same_weights(tmp_path):
    settings = Settings(budget=1000, args="predicted")
    run = Run(tmp_path / "r", settings)
    run.check_predictor("a" * 64)
    run.append({"concept": "c", "iteration": 0, "found": False, "program": None})
    again = Run(tmp_path / "r", settings)
    again.check_predictor("a" * 64)  # the same weights: resumes
    with pytest.raises(DataFileError, match="other argument-predictor weights"):
        Run(tmp_path / "r", settings).check_predictor("b" * 64)
    (tmp_path / "r2").mkdir()
    old = Run(tmp_path / "r2", settings)  # records made before the weights were recorded
    old.append({"concept": "c", "iteration": 0, "found": False, "program": None})
    with pytest.raises(DataFileError, match="do not say which"):
        Run(tmp_path / "r2", settings).check_predictor("a" * 64)
