"""`vcc bench search` on a tiny setting: a stamped result whose batched and scalar sides
agree (speed itself measured, never asserted); `vcc bench misses`: why a run missed."""

from __future__ import annotations

import json

import pytest

from vcc.cli import build_parser, main
from vccjax.errors import DataFileError


def test_bench_search_compares_batched_and_scalar_on_the_same_concepts(tmp_path, capsys):
    out = tmp_path / "search.json"
    argv = ["bench", "search", "--concepts", "remove_bottom_obj,change_all_objs_color", "--budget", "2000",
            "--width", "2", "--out", str(out)]  # examples: the dataset shipped in the package
    assert main(argv) == 0
    text = capsys.readouterr().out
    r = json.loads(out.read_text())
    assert r["results_agree"] is True and r["found"] >= 1
    assert r["batched"]["programs_searched"] == r["scalar"]["programs_searched"] > 0
    assert r["batched"]["nodes"] == r["scalar"]["nodes"]
    assert r["ratio"] > 0 and f"{r['ratio']}x" in text
    assert {"date", "commit", "machine", "command"} <= set(r) and r["machine"]["cores"] >= 1
    again = build_parser().parse_args(r["command"].split()[1:])  # the stamped command reproduces the run
    assert {k: v for k, v in vars(again).items() if k != "fn"} == {
        k: v for k, v in vars(build_parser().parse_args(argv)).items() if k != "fn"}


def test_bench_search_can_start_from_the_shipped_library():
    """`--model library`: the chains search with the shipped library's vocabulary
    (atoms and subroutines) and model, as `vcc learn` does."""
    import numpy as np

    from search.library import load
    from vcc.bench import _search_jobs

    a = build_parser().parse_args(["bench", "search", "--concepts", "remove_bottom_obj", "--model", "library"])
    names, jobs = _search_jobs(a)
    lib = load(None)
    (chain, task), = jobs
    assert names == ["remove_bottom_obj"] and task.n_examples >= 1
    assert chain.vocab == lib.vocab and lib.vocab.bodies  # the library's subroutines, not the atoms alone
    assert np.array_equal(chain.model.logp, lib.model.logp)


def test_bench_search_scalar_side_can_run_a_sample(tmp_path, capsys):
    """`--scalar-sample k`: the scalar side searches k of the concepts, evenly spread; the
    results are compared on those, and the ratio is of programs run per second."""
    from vcc.bench import scalar_sample

    assert scalar_sample(64, 4) == [0, 16, 32, 48] and scalar_sample(3, 5) == [0, 1, 2] == scalar_sample(3, None)
    assert len(scalar_sample(7, 3)) == 3 and len(set(scalar_sample(10, 10))) == 10
    out = tmp_path / "search.json"
    argv = ["bench", "search", "--concepts", "remove_bottom_obj,change_all_objs_color", "--budget", "2000",
            "--width", "2", "--scalar-sample", "1", "--out", str(out)]
    assert main(argv) == 0
    r = json.loads(out.read_text())
    assert r["scalar"]["concepts"] == ["remove_bottom_obj"] and r["results_agree"] is True
    b, s = r["batched"], r["scalar"]
    expected = (b["programs_run"] / b["seconds"]) / (s["programs_run"] / s["seconds"])
    assert abs(r["ratio"] - expected) <= 0.03 * expected + 0.01  # from the seconds as stored (rounded)
    assert "scalar over 1" in capsys.readouterr().out


def test_bench_misses_names_the_cheapest_known_program_and_its_rank(tmp_path):
    """A missed concept is spelt by its cheapest known program (its reference program, or a
    cheaper one another run found that fits this run's examples) under the run's last
    model; the rank is the same whatever the budget, and it is past a budget of 1."""
    from search.model import MarkovModel, Vocabulary
    from vcc.misses import why_missed
    from vccjax.world.concepts import reference_program

    missed, found = "move_to_top_edge", "remove_bottom_obj"
    size = Vocabulary().size

    def run(folder, budget):
        folder.mkdir()
        settings = {"budget": budget, "order": 1, "args": "oracle", "subroutines": True, "epsilon": 0.1,
                    "max_iterations": 1, "max_subroutines": 100, "delta": 0.01}
        (folder / "run.json").write_text(json.dumps({"format": "vccjax-induce", "version": 1, "settings": settings}))
        rows = [{"concept": missed, "found": False, "iteration": 0},
                {"concept": found, "found": True, "iteration": 0, "program": reference_program(found).text()}]
        (folder / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
        (folder / "model-0.json").write_text(json.dumps({"iteration": 0, "order": 1, "subroutines": [],
                                                         "logp": MarkovModel.uniform(size, 1).logp.tolist()}))
        return folder

    small, large = why_missed(run(tmp_path / "small", 1)), why_missed(run(tmp_path / "large", 10**12))
    assert small["found"] == 1 and small["concepts"] == 2 and [r["concept"] for r in small["misses"]] == [missed]
    a, b = small["misses"][0], large["misses"][0]
    assert a["program"] == "reference" and a["rank"] == b["rank"] > 1 and a["nats"] == b["nats"] > 0
    assert (a["why"], b["why"]) == ("past the budget", "within the budget")
    # a shorter program found by another run for the same concept is the one spelt
    ref = reference_program(missed)
    other = tmp_path / "other"
    other.mkdir()
    assert ref.text().endswith("; release_object")  # an object left held stays where it was put
    shorter = ref.text().removesuffix("; release_object")
    moves_nothing = "scene_parse; top_down_attend"  # cheaper still, but fits no example
    (other / "results.jsonl").write_text("".join(json.dumps({"concept": missed, "found": True, "program": p}) + "\n"
                                                 for p in (moves_nothing, shorter)))
    c = why_missed(tmp_path / "large", [tmp_path / "other"])["misses"][0]
    assert c["program"] == shorter and c["nats"] < b["nats"] and c["rank"] < b["rank"]
    # any concept the run searched, found or not, ranked under a chosen model: the found one's
    # reference program is shorter than the missed one's, so it ranks before it
    both = why_missed(tmp_path / "large", model_index=0, concepts=[found, missed])
    assert [r["concept"] for r in both["misses"]] == [found, missed] and both["model"] == "model-0.json"
    assert both["misses"][0]["rank"] < both["misses"][1]["rank"] == b["rank"]
    with pytest.raises(DataFileError, match="no model-3.json"):
        why_missed(tmp_path / "large", model_index=3)
    with pytest.raises(DataFileError, match="searched no concept remove_top_obj"):
        why_missed(tmp_path / "large", concepts=["remove_top_obj"])
