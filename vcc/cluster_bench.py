"""`vcc bench cluster`: one process against Ray workers on the same search, one run.

The jobs are those of `vcc bench search` (its concept sample, model and arguments): the
first iteration of explore-compress when the model is uniform. Each side runs them
twice, and the second run is timed, so compiling (once per worker process) is measured
apart. The results must agree concept by concept. Per-concept costs are kept, so the
time on a larger cluster can be worked out from them (docs/cluster.md).
"""

from __future__ import annotations

import argparse
import time

from vccjax import files, runtime


def cmd_bench_cluster(a: argparse.Namespace) -> int:
    from search.cluster import ClusterSearcher, ray_module
    from search.explore import Explorer
    from vcc.bench import _search_jobs, stamp

    ray_module()
    if a.width < a.workers:
        raise ValueError(f"--width {a.width}: at least --workers ({a.workers}), each worker takes width/workers")
    runtime.prepare()
    names, jobs = _search_jobs(a)

    def timed(searcher) -> tuple[dict, float, float]:
        t0 = time.perf_counter()
        searcher.search_many(jobs, a.budget, lambda j, r: None)  # compiles what it meets
        first = time.perf_counter() - t0
        got: dict = {}
        t0 = time.perf_counter()
        searcher.search_many(jobs, a.budget, got.__setitem__)
        return got, time.perf_counter() - t0, first

    single, single_s, single_first = timed(Explorer(width=a.width))
    with ClusterSearcher(workers=a.workers, width=a.width // a.workers) as searcher:
        workers = len(searcher.actors)
        spread, spread_s, spread_first = timed(searcher)
    agree = all((single[j].found, single[j].text, single[j].rank) == (spread[j].found, spread[j].text, spread[j].rank)
                for j in range(len(jobs)))
    run = sum(r.programs for r in single.values())
    report = {
        **stamp(a, "cluster"), "benchmark": "cluster", "concepts": names, "budget": a.budget, "model": a.model,
        "args": "oracle", "found": sum(r.found for r in single.values()), "results_agree": agree,
        "single": {"width": a.width, "seconds": round(single_s, 3), "first_run_seconds_with_compile":
                   round(single_first, 2), "programs_run_per_second": round(run / single_s)},
        "cluster": {"workers": workers, "width": a.width // a.workers, "seconds": round(spread_s, 3),
                    "first_run_seconds_with_compile": round(spread_first, 2),
                    "programs_run_per_second": round(run / spread_s)},
        "speedup": round(single_s / spread_s, 2),
        "per_concept_seconds": {names[j]: round(r.seconds, 4) for j, r in sorted(single.items())},
    }
    files.write_json(a.out, report)
    print(f"{len(names)} concepts x {a.budget}, {a.model} model, oracle arguments: "
          f"{'same programs' if agree else 'RESULTS DIFFER'} on both sides; {report['found']} found")
    print(f"one process (width {a.width}): {single_s:.2f} s   (first run, compiling: {single_first:.1f} s)")
    print(f"{workers} Ray workers (width {a.width // a.workers} each): {spread_s:.2f} s   "
          f"(first run, compiling: {spread_first:.1f} s)")
    print(f"speed-up: {report['speedup']}x   -> {a.out}")
    return 0 if agree else 1


def add_command(bsub) -> None:
    from vcc.bench import _concept_flags

    c = bsub.add_parser("cluster", help="one process against Ray workers on the same search, one run",
                        description="Search the concepts of `vcc bench search` in one process and on "
                                    "--workers Ray workers (a local cluster, or $RAY_ADDRESS): seconds, "
                                    "speed-up, agreement; compile time measured apart (a first run).")
    _concept_flags(c, 64)
    c.add_argument("--budget", type=runtime.count(1, 10**10), default=100_000,
                   help="programs per concept (default 100000)")
    c.add_argument("--model", choices=["uniform", "reference", "library"], default="uniform",
                   help="as `vcc bench search --model` (default uniform: explore-compress iteration 0)")
    c.add_argument("--workers", type=runtime.count(1, 4096), default=2, help="Ray workers (default 2)")
    c.add_argument("--width", type=runtime.count(1, 4096), default=64,
                   help="concepts in lockstep in the one process; each worker takes width/workers (default 64)")
    c.add_argument("--out", default="benchmarks/results/cluster.json", type=runtime.out_file(".json"),
                   help="result JSON")
    c.set_defaults(fn=cmd_bench_cluster)
