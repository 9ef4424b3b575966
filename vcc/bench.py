"""`vcc bench`: speed measured, never asserted. Two implementations are compared as a
ratio measured in the same run, compile time is reported apart, and every result is
stamped with the date, commit, machine and the exact command."""

from __future__ import annotations

import argparse
import time
from collections import Counter
from pathlib import Path

from vccjax import files, runtime
from vccjax.errors import VCCError


def stamp(a: argparse.Namespace, benchmark: str) -> dict:
    """Where and when a measurement was made, and the command that made it (rebuilt from the
    parsed settings, so a bench called from Python is stamped as truly as one from the shell)."""
    return runtime.provenance(command_line(a, benchmark))


def command_line(a: argparse.Namespace, benchmark: str) -> str:
    """The `vcc bench` command that reproduces a run: its parsed options, in order."""
    parts = ["vcc", "bench", benchmark]
    for k, v in vars(a).items():
        if k in ("fn", "command", "action") or v is None or v is False:
            continue
        flag = "--" + k.replace("_", "-")
        parts += [flag] if v is True else [flag, str(v)]
    return " ".join(parts)


def _search_jobs(a: argparse.Namespace):
    from search.chain import Chain
    from vccjax.world.concepts import concept_list
    from search.task import Task
    from search.induce import Settings, argument_logp
    from search.model import MarkovModel, Vocabulary
    from vccjax.world.concepts import all_concepts, concept_names
    from vccjax.world.dataset import dataset_for

    names = concept_list(a.concepts) if a.concepts else concept_names()[:: max(1, 546 // a.sample)][: a.sample]
    ds = dataset_for(names, 0, a.dataset, progress=False)
    vocab = Vocabulary()
    if a.model == "uniform":
        model = MarkovModel.uniform(vocab.size, 1)
    elif a.model == "library":  # what explore-compress learned: its model and subroutines, as vcc learn starts
        from search.library import load

        lib = load(None)
        vocab, model = lib.vocab, lib.model
    else:  # a late explore-compress iteration's model, stood in for by the reference programs
        model = MarkovModel.fit([list(p.ops) for p in all_concepts().values()], vocab.size, 1, 0.1)
    settings = Settings(args="oracle")
    return names, [(Chain(vocab, model, argument_logp(settings, c)), Task.from_pairs(ds.pairs(c, "train")))
                   for c in names]


def cmd_bench_search(a: argparse.Namespace) -> int:
    """The same concepts searched by the batched explorer (all concepts in lockstep) and by
    the scalar-driven one, same chains and budget: programs/s and their ratio."""
    from vccjax.runtime import enable_compile_cache
    from search.explore import Explorer
    from search.scalar import ScalarExplorer

    enable_compile_cache()
    names, jobs = _search_jobs(a)
    explorer = Explorer(width=a.width)
    warm: dict = {}
    t0 = time.perf_counter()
    explorer.search_many(jobs, a.budget, warm.__setitem__)  # compiles every (op, size) it meets
    first = time.perf_counter() - t0
    batched: dict = {}
    t0 = time.perf_counter()
    explorer.search_many(jobs, a.budget, batched.__setitem__)
    jax_s = time.perf_counter() - t0
    sample = scalar_sample(len(jobs), a.scalar_sample)
    scalar = {}
    t0 = time.perf_counter()
    for j in sample:
        chain, task = jobs[j]
        scalar[j] = ScalarExplorer().search(chain, task, a.budget)
    scalar_s = time.perf_counter() - t0

    def rates(results: dict, seconds: float) -> dict:
        covered = sum(r.rank if r.found else r.budget for r in results.values())
        nodes = sum(r.nodes for r in results.values())
        return {"seconds": round(seconds, 4), "programs_searched": covered, "nodes": nodes,
                "programs_run": sum(r.programs for r in results.values()),
                "programs_per_second": round(covered / seconds), "nodes_per_second": round(nodes / seconds)}

    agree = all((batched[j].found, batched[j].text, batched[j].rank) == (scalar[j].found, scalar[j].text,
                                                                         scalar[j].rank) for j in sample)
    b_rates, s_rates = rates(batched, jax_s), rates(scalar, scalar_s)
    if len(sample) == len(jobs):  # the same work on both sides: the ratio of their times
        ratio = scalar_s / jax_s
    else:  # the scalar side ran a sample: the ratio of programs run to the end per second
        ratio = (b_rates["programs_run"] / jax_s) / max(s_rates["programs_run"] / scalar_s, 1e-9)
    report = {
        **stamp(a, "search"), "benchmark": "search", "concepts": names, "budget": a.budget, "model": a.model,
        "args": "oracle", "width": a.width, "found": sum(r.found for r in batched.values()),
        "batched": {**b_rates, "first_run_seconds_with_compile": round(first, 2)},
        "scalar": {**s_rates, "concepts": [names[j] for j in sample]}, "results_agree": agree,
        "ratio": round(ratio, 2),
    }
    files.write_json(a.out, report)
    b, s = report["batched"], report["scalar"]
    print(f"{len(names)} concepts, budget {a.budget}, {a.model} model, oracle arguments; {report['found']} found "
          f"by the batched search; on the {len(sample)} both ran: {'same programs' if agree else 'RESULTS DIFFER'}")
    print(f"{'':10}{'seconds':>10}{'programs/s':>14}{'nodes/s':>12}")
    print(f"{'batched':10}{b['seconds']:>10}{b['programs_per_second']:>14}{b['nodes_per_second']:>12}"
          f"   (first run, compiling: {b['first_run_seconds_with_compile']} s)")
    print(f"{'scalar':10}{s['seconds']:>10}{s['programs_per_second']:>14}{s['nodes_per_second']:>12}")
    how = ("scalar time / batched time" if len(sample) == len(jobs)
           else f"programs run/s, batched over {len(jobs)} concepts / scalar over {len(sample)}")
    print(f"ratio ({how}): {report['ratio']}x   -> {a.out}")
    return 0 if agree else 1


def scalar_sample(n: int, k: int | None) -> list[int]:
    """The jobs the scalar side runs: all, or k of the n spread evenly (the first included)."""
    if k is None or k >= n:
        return list(range(n))
    return sorted({round(i * n / k) for i in range(k)})


def _ints(text: str) -> list[int]:
    try:
        return [int(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise ValueError(f"expected comma-separated integers, got {text!r}") from None


def cmd_bench_emulator(a: argparse.Namespace) -> int:
    """The search's instruction stream stepped by the batched JAX emulator and by the
    reference interpreter from the same parent states: programs/s and their ratio, per
    instruction too; sweeps over batch size, objects per scene and raster size."""
    import numpy as np

    from vcc import emulator_bench as eb
    from vccjax.machine.instructions import NAMES
    from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
    from vccjax.world.scenes import random_scene

    batches, objects, rasters = _ints(a.batch), _ints(a.objects), _ints(a.raster)
    a.model = "reference"  # a late iteration's model: the deep, mixed stream of the search's later work
    names, jobs = _search_jobs(a)
    t0 = time.perf_counter()
    stream = eb.record_stream(jobs, a.per_concept)
    record_s = time.perf_counter() - t0
    examples = [[x for x, _ in task.pairs] for _, task in jobs]
    ops = Counter(NAMES[c[2]] for c in stream)

    def run(scenes, cfg, batch):
        return eb.measure(eb.prepare(stream, scenes, cfg), batch, a.repeats)

    main = run(examples, DEFAULT_CONFIG, batches[0])
    sweeps = {"batch": [main] + [run(examples, DEFAULT_CONFIG, b) for b in batches[1:]], "objects": [], "raster": []}
    rng = np.random.default_rng(0)
    for n in objects:
        scenes = [[random_scene(rng, n, pointer=True) for _ in ex] for ex in examples]
        sweeps["objects"].append({"objects": n, **run(scenes, DEFAULT_CONFIG, batches[0])})
    for r in rasters:
        sweeps["raster"].append({"raster": r, **run(examples, VCCConfig(raster=r), batches[0])})
    report = {**stamp(a, "emulator"), "benchmark": "emulator", "concepts": names, "model": "reference",
              "stream": {"programs": len(stream), "per_concept": a.per_concept, "record_seconds": round(record_s, 2),
                         "instructions": dict(ops.most_common())},
              "main": main, "sweeps": sweeps}
    files.write_json(a.out, report)
    every = [main] + sweeps["batch"][1:] + sweeps["objects"] + sweeps["raster"]
    agree = all(m["agree"] for m in every)
    print(f"{len(stream)} programs from the search of {len(names)} concepts ({len(ops)} instructions), "
          f"each stepped on {main['examples']} examples; JAX and reference "
          + ("agree on every one" if agree else "DISAGREE"))
    print(f"{'setting':22}{'JAX prog/s':>12}{'ref prog/s':>12}{'ratio':>8}{'compile s':>11}")
    for label, m in ([(f"batch {m['batch']}", m) for m in sweeps["batch"]]
                     + [(f"{m['objects']} objects", m) for m in sweeps["objects"]]
                     + [(f"raster {m['raster']}", m) for m in sweeps["raster"]]):
        print(f"{label:22}{m['jax_programs_per_second']:>12}{m['reference_programs_per_second']:>12}"
              f"{m['ratio']:>8}{m['first_pass_seconds_with_compile']:>11}")
    print(f"per instruction (batch {main['batch']}):")
    for name, r in sorted(main["per_instruction"].items(), key=lambda x: -x[1]["programs"]):
        print(f"  {name:30}{r['programs']:>7}{r['jax_per_second']:>12}{r['reference_per_second']:>12}{r['ratio']:>8}")
    print(f"ratio (reference time / JAX time), mixed stream: {main['ratio']}x   -> {a.out}")
    return 0 if agree else 1


def cmd_bench_reproduce(a: argparse.Namespace) -> int:
    """Run the chosen rows (each resumable), then write the results JSON and the report."""
    from vccjax.runtime import enable_compile_cache
    from vccjax.world.concepts import concept_list
    from vcc import reproduce as rp

    rows = rp.select(a.rows)
    if a.list:
        for r in rp.ROWS:
            print(f"{r.name:22}{r.what}   [paper: {r.paper}]")
        return 0
    if a.scale <= 0:
        raise ValueError(f"--scale must be positive, got {a.scale}")
    cluster = runtime.on_cluster(a)
    names = concept_list(a.concepts)
    tag = rp.concept_tag(a.concepts, names)
    runs = Path(a.runs)
    searcher = None
    if rows:
        enable_compile_cache()
        if cluster:  # each iteration's concepts in chunks of --width to Ray workers
            from search.cluster import ClusterSearcher

            searcher = ClusterSearcher(workers=a.workers, width=a.width)
    interrupted = False
    try:
        for k, row in enumerate(rows):
            out = rp.folder(runs, row, tag, a.scale)
            print(f"[{k + 1}/{len(rows)}] {row.name}: {row.what} -> {out}", flush=True)
            if rp.finished_otherwise(out, rp.scaled(row, a.scale)) is not None:
                print(f"  kept: {out} holds this row finished under settings since changed (its run.json says "
                      "which; the report gives them); move the folder aside to run it with today's")
                continue
            if a.redo_last_pass:
                aside = rp.set_last_pass_aside(out)
                print(f"  its last pass searched anew; the earlier one's records -> {aside}" if aside else
                      "  no finished last pass to search anew")
            try:
                s = rp.run_row(row, names, out, a.scale, a.dataset, a.width, not a.quiet, searcher)
            except KeyboardInterrupt:
                interrupted = True
                print(f"interrupted: {out} resumes where it stopped when this command is run again")
                break
            print(f"  induced {s['found']} of {s['concepts']}, {s['exact_on_all_test_pairs']} exact on all test "
                  f"pairs, {s['wall_seconds']:.0f} s")
    finally:
        if searcher is not None:
            searcher.close()
    _write_report(a, runs)
    return 130 if interrupted else 0


def _write_report(a: argparse.Namespace, runs: Path) -> int:
    from vcc import report

    for flag, path in (("--others", a.others), ("--robot", a.robot), ("--compiled", a.compiled)):
        if path and not Path(path).is_dir():  # a typo would leave its tables out without a word
            raise VCCError(f"{flag} {path}: {'not a folder' if Path(path).exists() else 'no such folder'} "
                           f"(give '' to leave its tables out)")
    st = stamp(a, "reproduce")
    rows = report.collect_rows(runs)
    out = Path(a.out)
    text = report.render(out.parent, rows, st, Path(a.others) if a.others else None,
                         Path(a.robot) if a.robot else None, runs,
                         Path(a.compiled) if a.compiled else None)  # all read and checked first
    files.write_json(out, {**st, "benchmark": "reproduce", "runs": str(runs), "rows": rows})
    files.write_whole(a.report, text)
    print(f"{len(rows)} row runs -> {out}; report -> {a.report}")
    return 0


def cmd_bench_report(a: argparse.Namespace) -> int:
    if not Path(a.runs).is_dir():  # `vcc bench reproduce` makes it; a report of none would be empty
        raise VCCError(f"--runs {a.runs}: {'not a folder' if Path(a.runs).exists() else 'no such folder'} "
                       f"of row runs")
    return _write_report(a, Path(a.runs))


def _report_flags(p: argparse.ArgumentParser) -> None:
    p.add_argument("--runs", default="benchmarks/reproduce", help="row run folders (default benchmarks/reproduce)")
    p.add_argument("--out", default="benchmarks/results/reproduce.json", type=runtime.out_file(".json"),
                   help="results JSON; the report reads every result JSON beside it")
    p.add_argument("--report", default="benchmarks/REPORT.md", type=runtime.out_file(".md"),
                   help="the generated report")
    p.add_argument("--others", default="benchmarks/induction",
                   help="committed induction runs to list apart (default benchmarks/induction; '' for none)")
    p.add_argument("--robot", default="benchmarks/robot",
                   help="arm suites (folders with a summary.json) to list (default benchmarks/robot; '' for none)")
    p.add_argument("--compiled", default="benchmarks/compile",
                   help="cold-cache `vcc induce` runs whose compile time the targets table reads "
                        "(default benchmarks/compile; '' for none)")


def _concept_flags(p: argparse.ArgumentParser, sample: int) -> None:
    p.add_argument("--concepts", type=runtime.name_list,
                   help="comma-separated concepts (default: --sample spread over all 546)")
    p.add_argument("--sample", type=runtime.count(1, 10**4), default=sample,
                   help=f"concepts, evenly spread (default {sample})")
    p.add_argument("--dataset", help="a built dataset folder (default: the one shipped with vccjax)")


def add_commands(sub) -> None:
    b = sub.add_parser("bench", help="benchmarks: measured speed, stamped with machine and commit")
    bsub = b.add_subparsers(dest="action", required=True, metavar="BENCHMARK")
    s = bsub.add_parser("search", help="batched search vs the scalar-driven search, same concepts, one run",
                        description="Search the same concepts with the batched explorer (many concepts "
                                    "in lockstep on the JAX emulator) and with the scalar reference "
                                    "interpreter; print programs/s (counted as the paper counts them) "
                                    "and the ratio. Compile time is measured apart (a first run).")
    _concept_flags(s, 64)
    s.add_argument("--budget", type=runtime.count(1, 10**10), default=100_000,
                   help="programs per concept (default 100000)")
    s.add_argument("--model", choices=["uniform", "reference", "library"], default="uniform",
                   help="uniform: explore-compress iteration 0; reference: an order-1 model fitted "
                        "on the reference programs, standing in for a late iteration (deeper trees); "
                        "library: the shipped library (model and subroutines), as vcc learn searches")
    s.add_argument("--width", type=runtime.count(1, 4096), default=32, help="concepts in lockstep (default 32)")
    s.add_argument("--scalar-sample", type=runtime.count(1, 10**4),
                   help="the scalar side searches only this many of the concepts, evenly spread (default: all); "
                        "the ratio is then of programs run to the end per second")
    s.add_argument("--out", default="benchmarks/results/search.json", type=runtime.out_file(".json"),
                   help="result JSON")
    s.set_defaults(fn=cmd_bench_search)
    e = bsub.add_parser("emulator", help="batched JAX emulator vs reference interpreter on a search's stream",
                        description="Record the children a real search steps (the scalar-driven search of "
                                    "--sample concepts under a late iteration's model), then step each by its "
                                    "last instruction from the same parent states on both machines: programs/s, "
                                    "per instruction and overall, and their ratio in the same run. Sweeps over "
                                    "batch size, objects per scene and raster size; compile time apart.")
    _concept_flags(e, 16)
    e.add_argument("--per-concept", type=runtime.count(1, 10**6), default=500,
                   help="children recorded per concept (default 500)")
    e.add_argument("--batch", default="1024,4096", type=runtime.counts(1, 2**16),
                   help="rows per device call; the first is the main one")
    e.add_argument("--objects", default="2,5,8", type=runtime.counts(1, 10, none_ok=True),
                   help="objects per random scene for the objects sweep")
    e.add_argument("--raster", default="32,128", type=runtime.counts(8, 512, none_ok=True),
                   help="raster sizes for the raster sweep (the default is 64)")
    e.add_argument("--repeats", type=runtime.count(1, 100), default=3, help="timed passes (the best is kept)")
    e.add_argument("--out", default="benchmarks/results/emulator.json", type=runtime.out_file(".json"),
                   help="result JSON")
    e.set_defaults(fn=cmd_bench_emulator)
    r = bsub.add_parser("reproduce", help="the paper's induction experiments as rows beside its figures",
                        description="Run the paper's experiments (budgets, order 0/1, arguments uniform/"
                                    "predicted/predicted+fixation, the learning curve) as explore-compress "
                                    "runs, one folder per row under --runs; rerunning resumes. Then write "
                                    "the results JSON and benchmarks/REPORT.md (rows not run say so).")
    r.add_argument("--rows", default="all", type=runtime.name_list,
                   help="comma-separated rows, 'all' (default) or 'none' (report only)")
    r.add_argument("--list", action="store_true", help="list the rows and the paper's figures, run nothing")
    r.add_argument("--concepts", type=runtime.name_list, default="all",
                   help="'all' (default), 'demo' or a comma-separated list")
    r.add_argument("--scale", type=runtime.number(0, 1, above=True), default=1.0,
                   help="multiply every row's budget (a tiny CI run; the folder name says so)")
    r.add_argument("--dataset", help="a built dataset folder (default: the one shipped with vccjax)")
    r.add_argument("--width", type=runtime.count(1, 4096), default=32,
                   help="concepts searched in lockstep (default 32)")
    runtime.cluster_flags(r, "search each iteration's concepts on Ray workers, --width concepts a chunk; "
                             "the same results")
    r.add_argument("--redo-last-pass", action="store_true",
                   help="search each finished row's last pass anew (after a change to it alone); the earlier "
                        "pass's records are kept as last-pass-K.jsonl in the row folder")
    r.add_argument("--quiet", action="store_true", help="no progress bars")
    _report_flags(r)
    r.set_defaults(fn=cmd_bench_reproduce)
    g = bsub.add_parser("report", help="regenerate benchmarks/REPORT.md from the measured results (runs nothing)")
    _report_flags(g)
    g.set_defaults(fn=cmd_bench_report)
    from vcc import cluster_bench, learn_bench, misses

    learn_bench.add_command(bsub)
    cluster_bench.add_command(bsub)
    misses.add_command(bsub)
