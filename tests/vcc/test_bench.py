"""`vcc bench`: runs on a tiny setting, and writes a stamped result whose two
implementations agree (speed itself is measured, never asserted)."""

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


def test_bench_emulator_steps_a_recorded_search_stream_on_both_machines(tmp_path, capsys):
    out = tmp_path / "emulator.json"
    argv = ["bench", "emulator", "--concepts", "remove_bottom_obj,move_to_middle", "--per-concept", "30",
            "--batch", "32", "--objects", "3", "--raster", "", "--repeats", "1", "--out", str(out)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    r = json.loads(out.read_text())
    assert r["stream"]["programs"] == 60 and sum(r["stream"]["instructions"].values()) == 60
    m = r["main"]
    assert m["agree"] is True and m["programs"] == 60 and m["examples"] == 10
    assert m["jax_programs_per_second"] > 0 and m["reference_programs_per_second"] > 0
    assert sum(v["programs"] for v in m["per_instruction"].values()) == 60
    assert [x["objects"] for x in r["sweeps"]["objects"]] == [3] and r["sweeps"]["objects"][0]["agree"] is True
    assert f"mixed stream: {m['ratio']}x" in text and {"date", "commit", "machine", "command"} <= set(r)


def test_the_recorded_stream_is_what_the_search_steps_first():
    """Children in the search's order: the first are scene_parse's, then its children."""
    from search.chain import Chain
    from search.explore import Task
    from search.induce import Settings, argument_logp
    from search.model import MarkovModel, Vocabulary
    from vcc.emulator_bench import record_stream
    from vccjax.world.dataset import dataset_for
    from vccjax.machine.instructions import OP

    ds = dataset_for(["remove_bottom_obj"], 0, None, progress=False)
    chain = Chain(Vocabulary(), MarkovModel.uniform(Vocabulary().size, 1),
                  argument_logp(Settings(args="oracle"), "remove_bottom_obj"))
    stream = record_stream([(chain, Task.from_pairs(ds.pairs("remove_bottom_obj", "train")))], 50)
    assert len(stream) == 50 and stream[0][1].ops == () and stream[0][2] == OP["scene_parse"]
    assert all(len(p) == 0 or p.ops[0] == OP["scene_parse"] for _, p, _, _ in stream)


def _emulator_result(date: str, commit: str, ratio: float, per_instruction: dict, k: int) -> dict:
    """A small emulator result of the shape `vcc bench emulator` writes (its figures made up,
    scaled by k so that two files' tables differ)."""
    def sweep(key, value, jax_rate, ref_rate):
        return {key: value, "jax_programs_per_second": jax_rate, "reference_programs_per_second": ref_rate,
                "ratio": round(jax_rate / ref_rate, 2), "first_pass_seconds_with_compile": 1.25, "agree": True}

    return {"date": date, "commit": commit, "command": f"vcc bench emulator --out {commit}.json",
            "machine": {"cores": 3, "cpu": "Test CPU", "python": "3.11", "jax": "0.0.1", "devices": ["cpu:0"]},
            "benchmark": "emulator", "concepts": ["a", "b", "c"], "model": "reference",
            "stream": {"programs": 123, "per_concept": 41},
            "main": {"ratio": ratio, "agree": True, "per_instruction": per_instruction},
            "sweeps": {"batch": [sweep("batch", 64 * k, 12345 * k, 2345)],
                       "objects": [sweep("objects", 5 + k, 5000 * k, 999)],
                       "raster": [sweep("raster", 32 * k, 7777 * k, 111)]}}


def test_bench_report_reads_result_files_and_marks_a_partial_row(tmp_path, capsys):
    """The report prints what its result files hold: each file's stamp, its sweeps and
    per-instruction ratios, the latest file's ratio against the target; a run folder cut
    short is marked partial. The result files are written here, their figures made up."""
    from vcc.report import TARGETS

    res = tmp_path / "res"
    res.mkdir()
    older = _emulator_result("2031-01-01T00:00:00+00:00", "aaaa111", 31.5,
                             {"grab_object": {"ratio": 9.0, "programs": 3}}, k=1)
    latest = _emulator_result("2031-02-01T00:00:00+00:00", "bbbb222", 3.07,
                              {"next_object": {"ratio": 1.5, "programs": 2},
                               "top_down_attend": {"ratio": 4.25, "programs": 7}}, k=2)
    (res / "emu-old.json").write_text(json.dumps(older))
    (res / "emu-new.json").write_text(json.dumps(latest))
    search = {"date": "2031-01-15T00:00:00+00:00", "commit": "cccc333", "command": "vcc bench search",
              "machine": latest["machine"], "benchmark": "search", "model": "order 1", "concepts": ["a", "b"],
              "budget": 2000, "ratio": 12.0, "results_agree": True,
              "batched": {"programs_per_second": 30000, "programs_run": 12000, "seconds": 2.0},
              "scalar": {"programs_per_second": 2500}}
    (res / "search-x.json").write_text(json.dumps(search))
    (res / "notes.json").write_text(json.dumps({"not": "a result"}))  # no "benchmark": not read
    partial = tmp_path / "runs" / "o1-uniform-0.5M"
    partial.mkdir(parents=True)
    (partial / "run.json").write_text(json.dumps({"settings": {}, "examples_sha256": {"a": "x", "b": "y"}}))
    (partial / "results.jsonl").write_text(json.dumps({
        "concept": "a", "found": True, "iteration": 0, "program": "scene_parse; top_down_attend", "covered": 5,
        "programs_run": 5, "nodes": 5, "seconds": 1.0, "test_correct": 50, "test_total": 50}) + "\n{cut")
    assert main(["bench", "report", "--runs", str(tmp_path / "runs"), "--out", str(res / "r.json"),
                 "--report", str(tmp_path / "REPORT.md"), "--others", ""]) == 0
    report = (tmp_path / "REPORT.md").read_text()
    # the target row: the latest emulator file (by date), its ratio against the target
    met = "yes" if latest["main"]["ratio"] >= TARGETS["emulator"] else "no"
    assert (f"| JAX emulator >= {TARGETS['emulator']:.0f}x the reference, mixed stream | {latest['main']['ratio']}x "
            f"(`emu-new.json`) | {met} |") in report
    assert f"| {older['main']['ratio']}x (`emu-old.json`)" not in report
    b = search["batched"]
    run_rate = round(b["programs_run"] / b["seconds"])
    assert (f"| {run_rate:,} run to the end on all examples; {b['programs_per_second']:,} searched as the paper "
            f"counts (`search-x.json`) | {'yes' if run_rate >= TARGETS['search'] else 'no'} (run to the end); "
            f"{'yes' if b['programs_per_second'] >= TARGETS['search'] else 'no'} (paper's count) |") in report
    # each file's stamp and tables, older first
    for name, d in (("emu-old.json", older), ("emu-new.json", latest)):
        m = d["machine"]
        stamp = (f"`{name}`: {d['date']}, commit {d['commit']}, {m['cores']} cores ({m['cpu']}), JAX {m['jax']} on "
                 f"{', '.join(m['devices'])}; command `{d['command']}`")
        assert stamp in report
        for label, key in (("batch", "batch"), ("objects", "objects"), ("raster", "raster")):
            sw = d["sweeps"][key][0]
            row = f"{label} {sw[key]}" if key != "objects" else f"{sw[key]} objects"
            assert (f"| {row} | {sw['jax_programs_per_second']:,} | {sw['reference_programs_per_second']:,} | "
                    f"{sw['ratio']} | {sw['first_pass_seconds_with_compile']} |") in report
        assert f"{d['stream']['programs']} children of a real search ({len(d['concepts'])} concepts)" in report
    assert report.index("`emu-old.json`:") < report.index("`emu-new.json`:")
    by_programs = sorted(latest["main"]["per_instruction"].items(), key=lambda x: -x[1]["programs"])
    assert "Per instruction (main setting): " + ", ".join(
        f"{n} {r['ratio']}x ({r['programs']})" for n, r in by_programs) in report
    assert "notes.json" not in report
    assert "1 of 2 (partial: run interrupted, resumable)" in report


def test_the_report_lists_each_arm_suite_with_its_failures_and_parse(tmp_path):
    """A suite's summary.json becomes one row: source, rate, failures by cause (most first),
    objects parsed exact; a folder without a suite summary is skipped."""
    from vcc.report import robot_section

    suite = tmp_path / "learned"
    suite.mkdir()
    summary = {"source": {"kind": "run", "path": "benchmarks/induction/x", "sha256": "ab"}, "scenarios": 8,
               "concepts": 3, "of": 4, "rollouts": 24, "success": 21,
               "failures": {"object dropped": 1, "parse wrong": 2},
               "parse": {"objects": 80, "objects_exact": 79, "scenes": 24, "scenes_exact": 23}}
    (suite / "summary.json").write_text(json.dumps(summary))
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "summary.json").write_text(json.dumps({"rollouts": 3}))  # a stress summary: not a suite
    lines = robot_section(tmp_path)
    rows = [x for x in lines if x.startswith(f"| `{suite}`")]
    assert len(rows) == 1 and len([x for x in lines if x.startswith("| `")]) == 1
    assert rows[0] == (f"| `{suite}` | run `benchmarks/induction/x` | 3 of 4 | 8 | 21 of 24 ({21 / 24:.1%}) | "
                       f"parse wrong 2, object dropped 1 | 79 of 80 ({79 / 80:.2%}) |")
    assert robot_section(tmp_path / "none") == []


def test_the_report_lists_each_stress_run_and_skips_suites(tmp_path):
    """A stress run's summary.json becomes one row (non-finite states, rate, failures by
    cause, most first); a suite's summary is not a stress run."""
    from vcc.report import stress_section

    run = tmp_path / "stress"
    run.mkdir()
    (run / "summary.json").write_text(json.dumps({
        "seed": 7, "batches": 2, "rollouts": 64, "rolled_out": 62, "non_finite": 0, "success": 59,
        "failures": {"misplaced": 1, "parse wrong": 2, "grasp slipped": 2}, "concepts": 40}))
    (tmp_path / "suite").mkdir()
    (tmp_path / "suite" / "summary.json").write_text(json.dumps({"source": {}, "parse": {}, "rollouts": 8}))
    lines = stress_section(tmp_path)
    rows = [x for x in lines if x.startswith("| `")]
    assert rows == [f"| `{run}` | 64 | 40 | 62 | 0 | 59 ({59 / 64:.1%}) | parse wrong 2, grasp slipped 2, misplaced 1 |"]
    assert stress_section(tmp_path / "none") == []


def test_the_report_tabulates_cluster_speedups_in_date_order():
    from vcc.report import cluster_section

    def run(date, model, one, workers_s):
        return {"benchmark": "cluster", "date": date, "model": model, "concepts": ["a", "b"], "budget": 1000,
                "single": {"seconds": one}, "cluster": {"workers": 2, "seconds": workers_s},
                "speedup": round(one / workers_s, 2), "results_agree": True}

    lines = cluster_section([("b.json", run("2031-02-01", "library", 9.0, 6.0)),
                             ("a.json", run("2031-01-01", "uniform", 1.0, 2.0))])
    rows = [x for x in lines if x.startswith("| `")]
    assert rows == ["| `a.json` | uniform | 2 x 1,000 | 1.0 | 2 | 2.0 | 0.5x | True |",
                    "| `b.json` | library | 2 x 1,000 | 9.0 | 2 | 6.0 | 1.5x | True |"]
    assert cluster_section([]) == []


def test_the_report_tabulates_the_camera_sweep_of_the_latest_file():
    from vcc.report import camera_section

    cond = {"nominal": {"objects": 40, "objects_exact": 39, "scenes": 10, "scenes_exact": 9,
                        "largest_centre_error_m": 0.0025}}
    old = {"benchmark": "robot-perception", "date": "2031-01-01", "conditions": {}}
    new = {"benchmark": "robot-perception", "date": "2031-02-01", "conditions": cond}
    lines = camera_section([("a.json", new), ("b.json", old)])
    assert f"| nominal | 39 of 40 ({39 / 40:.2%}) | 9 of 10 | 2.5 mm |" in lines
    assert any("`a.json`" in x for x in lines) and camera_section([]) == []


def test_the_report_gives_the_learning_benchmark_and_vcc_learns_wall_time():
    from vcc.report import learn_section

    learn = {"library, 10 examples": {"concepts": 4, "found": 3, "right": 2, "right_in_parts": 1}}
    ask = {"examples": 2, "first_right": 1, "first_wrong": 2, "wrong_reported_ambiguous": 2,
           "wrong_settled_by_one_query": 1, "right_reported_ambiguous": 0}
    timing = {"concept": "c", "instructions": 4, "pairs": 5, "cold_seconds": 50.5, "warm_seconds": 9.25, "cores": 2}
    old = {"benchmark": "learn", "date": "2031-01-01", "concepts": 4, "learn": {}, "ask": ask, "timing": None}
    new = {"benchmark": "learn", "date": "2031-02-01", "concepts": 4, "learn": learn, "ask": ask, "timing": timing}
    lines = learn_section([("old.json", old), ("new.json", new)])
    assert "| library, 10 examples | 3 of 4 | 2 of 4 | 1 |" in lines
    text = "\n".join(lines)
    assert "settled by one answered query 1" in text and "cold 50.5 s, warm 9.25 s on 2 cores" in text
    assert "`new.json`" in text and learn_section([]) == []


def test_the_report_gives_the_predictors_recall_and_extra_arguments():
    from vcc.report import argpred_section

    d = {"benchmark": "argpred-recall", "date": "2031-01-01", "commit": "abc", "command": "vcc argpred eval",
         "weights": "shipped", "weights_sha256": "0123456789ab", "members": 3, "split": "train", "concepts": 8,
         "recalled": 6, "recall": 6 / 8, "mean_extra_arguments": {"set_shape_attn": 0.5, "fill_color": 1.25},
         "missed": {"c1": {"fill_color": ["red", "blue"]}}}
    lines = argpred_section([("argpred-recall.json", d)])
    row = next(x for x in lines if x.startswith("| `argpred-recall.json`"))
    assert f"| 6 ({6 / 8:.1%}) |" in row and "set_shape_attn 0.50, fill_color 1.25" in row
    assert "c1: fill_color(red, blue)" in row and "`01234567`" in row
    assert "| 0.55 | 6 (" in row  # a file written before the threshold was recorded: the paper's 0.55
    higher = next(x for x in argpred_section([("argpred-recall-0.6.json", {**d, "threshold": 0.6})])
                  if x.startswith("| `argpred-recall-0.6.json`"))
    assert "| 0.6 | 6 (" in higher
    assert "| the network | 8 (train) |" in row  # a file written before `fill` was recorded
    gained = next(x for x in argpred_section([("g.json", {**d, "fill": "gained"})]) if x.startswith("| `g.json`"))
    assert "| the gained colours | the network | 8 (train) |" in gained  # before `filters`: the network's
    acted = next(x for x in argpred_section([("a.json", {**d, "fill": "gained", "filters": "acted"})])
                 if x.startswith("| `a.json`"))
    assert "| the gained colours | less those the objects acted on rule out | 8 (train) |" in acted
    raised = next(x for x in argpred_section([("r.json", {**d, "fill": "gained", "filters": "acted+raised"})])
                  if x.startswith("| `r.json`"))
    assert "| less those the objects acted on rule out, those the pairs point in raised | 8 (train) |" in raised
    many = {**d, "missed": {f"c{k}": {"fill_color": ["red"]} for k in range(11)}}
    long_row = next(x for x in argpred_section([("m.json", many)]) if x.startswith("| `m.json`"))
    assert "c7: fill_color(red)" in long_row and "c8:" not in long_row and "and 3 more (in the file)" in long_row
    assert argpred_section([]) == []


def test_a_run_with_the_last_pass_reads_with_and_without_it():
    from vcc.report import _cell, _pass

    s = {"complete": True, "found": 12, "concepts": 20, "found_in_last_pass": 3, "found_in_parts": 2}
    assert _cell(s) == "12 of 20 (9 before the last pass, which found 3, 2 of them in parts)"
    assert _cell({**s, "found_in_last_pass": 0}) == "12 of 20"
    assert _pass({"parts": 2}) == ", then a last pass (whole, then in up to 2 parts)" and _pass({}) == ""


def test_a_row_says_how_its_predicted_arguments_were_taken():
    from vcc.report import _predicted

    assert _predicted({"args": "oracle", "fill": "gained", "filters": "acted"}) == ""
    assert _predicted({"args": "predicted+fixation"}) == ""  # written before fill and filters: the network's
    both = _predicted({"args": "predicted", "arg_threshold": 0.6, "fill": "gained", "filters": "acted"})
    assert both == (", threshold 0.6, fill_color from the colours objects gain, "
                    "filters the objects acted on rule out dropped")
    assert _predicted({"args": "predicted", "fill": "gained", "filters": "acted+raised"}).endswith(
        "filters the objects acted on rule out dropped, those the pairs point in raised")


def test_bench_emulator_cuts_batches_as_the_search_does():
    """Each instruction's children go in the search's padded sizes (its cheapest cover,
    capped at the bench's batch), every child once; a carry op's holding rows apart when
    that makes the carrying calls smaller, as the search splits them."""
    import numpy as np

    from search.device_calls import BUCKETS, DeviceCalls
    from search.stepping import EMPTY_HANDED
    from vcc.emulator_bench import _parts, _pieces

    for n, batch in [(1, 1024), (17, 1024), (300, 1024), (658, 1024), (2500, 1024), (70, 64)]:
        pieces = _pieces(n, batch)
        calls = DeviceCalls([b for b in BUCKETS if b < batch] + [batch])
        assert [len(p) for p in pieces] == calls.piece_sizes(n)
        assert sorted(set(np.concatenate(pieces).tolist())) == list(range(n))
        assert all(len(p) <= batch and set(p.tolist()) <= set(range(n)) for p in pieces)

    def group_of(held):
        class Hand:
            pass

        class States:
            hand = Hand

        Hand.held = np.asarray(held)
        return {"rows": np.arange(len(held)), "states": States}

    carry = next(iter(EMPTY_HANDED))
    # 4 rows, rows 1 and 3 holding on some example: both halves pad to one 16-row call,
    # as the whole does, so splitting would only add a call.
    small = group_of([[-1, -1], [-1, 2], [-1, -1], [0, 0]])
    assert [p.tolist() for p in _parts(carry, small, 1024)] == [[0, 1, 2, 3]]
    # 40 rows (three 16-row calls), 10 holding (one 16-row call): the carry runs on 16
    # padded rows instead of 48, so the holding rows go apart.
    held = [[-1, 0] if r % 4 == 0 else [-1, -1] for r in range(40)]
    big = group_of(held)
    assert [p.tolist() for p in _parts(carry, big, 1024)] == [list(range(0, 40, 4)),
                                                             [r for r in range(40) if r % 4]]
    assert [p.tolist() for p in _parts(-1, big, 1024)] == [list(range(40))]


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
