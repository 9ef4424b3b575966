"""`vcc bench`: speed measured, never asserted. Two implementations are compared as a
ratio measured in the same run, compile time is reported apart, and every result is
stamped with the date, commit, machine and the exact command."""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path


def stamp() -> dict:
    """Where and when a measurement was made."""
    import jax

    cpu = platform.processor()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                cwd=Path(__file__).parent, timeout=10).stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        commit = None
    return {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "commit": commit, "command": "vcc " + " ".join(sys.argv[1:]) if sys.argv else None,
        "machine": {"cores": os.cpu_count(), "cpu": cpu, "python": platform.python_version(),
                    "jax": jax.__version__, "devices": [str(d) for d in jax.devices()]},
    }


def _search_jobs(a: argparse.Namespace):
    from search.chain import Chain
    from search.cli import concept_list
    from search.explore import Task
    from search.induce import Settings, argument_logp
    from search.model import MarkovModel, Vocabulary
    from vccjax.concepts import all_concepts, concept_names
    from vccjax.dataset import dataset_for

    names = concept_list(a.concepts) if a.concepts else concept_names()[:: max(1, 546 // a.sample)][: a.sample]
    ds = dataset_for(names, 0, a.dataset, progress=False)
    vocab = Vocabulary()
    if a.model == "uniform":
        model = MarkovModel.uniform(vocab.size, 1)
    else:  # a late explore-compress iteration's model, stood in for by the reference programs
        model = MarkovModel.fit([list(p.ops) for p in all_concepts().values()], vocab.size, 1, 0.1)
    settings = Settings(args="oracle")
    return names, [(Chain(vocab, model, argument_logp(settings, c)), Task.from_pairs(ds.pairs(c, "train")))
                   for c in names]


def cmd_bench_search(a: argparse.Namespace) -> int:
    """The same concepts searched by the batched explorer (all concepts in lockstep) and by
    the scalar-driven one, same chains and budget: programs/s and their ratio."""
    from search.cli import enable_compile_cache
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
    scalar = {}
    t0 = time.perf_counter()
    for j, (chain, task) in enumerate(jobs):
        scalar[j] = ScalarExplorer().search(chain, task, a.budget)
    scalar_s = time.perf_counter() - t0

    def rates(results: dict, seconds: float) -> dict:
        covered = sum(r.rank if r.found else r.budget for r in results.values())
        nodes = sum(r.nodes for r in results.values())
        return {"seconds": round(seconds, 2), "programs_searched": covered, "nodes": nodes,
                "programs_run": sum(r.programs for r in results.values()),
                "programs_per_second": round(covered / seconds), "nodes_per_second": round(nodes / seconds)}

    agree = all((batched[j].found, batched[j].text, batched[j].rank) == (scalar[j].found, scalar[j].text, scalar[j].rank)
                for j in range(len(jobs)))
    report = {
        **stamp(), "benchmark": "search", "concepts": names, "budget": a.budget, "model": a.model,
        "args": "oracle", "width": a.width, "found": sum(r.found for r in batched.values()),
        "batched": {**rates(batched, jax_s), "first_run_seconds_with_compile": round(first, 2)},
        "scalar": rates(scalar, scalar_s), "results_agree": agree,
        "ratio": round(scalar_s / jax_s, 2),
    }
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(report, indent=1))
    b, s = report["batched"], report["scalar"]
    print(f"{len(names)} concepts, budget {a.budget}, {a.model} model, oracle arguments; "
          f"{report['found']} found by both: {'same programs' if agree else 'RESULTS DIFFER'}")
    print(f"{'':10}{'seconds':>10}{'programs/s':>14}{'nodes/s':>12}")
    print(f"{'batched':10}{b['seconds']:>10}{b['programs_per_second']:>14}{b['nodes_per_second']:>12}"
          f"   (first run, compiling: {b['first_run_seconds_with_compile']} s)")
    print(f"{'scalar':10}{s['seconds']:>10}{s['programs_per_second']:>14}{s['nodes_per_second']:>12}")
    print(f"ratio (scalar time / batched time): {report['ratio']}x   -> {a.out}")
    return 0 if agree else 1


def add_commands(sub) -> None:
    b = sub.add_parser("bench", help="benchmarks: measured speed, stamped with machine and commit")
    bsub = b.add_subparsers(dest="action", required=True, metavar="BENCHMARK")
    s = bsub.add_parser("search", help="batched search vs the scalar-driven search, same concepts, one run",
                        description="Search the same concepts with the batched explorer (many concepts "
                                    "in lockstep on the JAX emulator) and with the scalar reference "
                                    "interpreter; print programs/s (counted as the paper counts them) "
                                    "and the ratio. Compile time is measured apart (a first run).")
    s.add_argument("--concepts", help="comma-separated concepts (default: --sample spread over all 546)")
    s.add_argument("--sample", type=int, default=64, help="concepts, evenly spread (default 64)")
    s.add_argument("--budget", type=int, default=100_000, help="programs per concept (default 100000)")
    s.add_argument("--model", choices=["uniform", "reference"], default="uniform",
                   help="uniform: explore-compress iteration 0; reference: an order-1 model fitted "
                        "on the reference programs, standing in for a late iteration (deeper trees)")
    s.add_argument("--width", type=int, default=32, help="concepts in lockstep (default 32)")
    s.add_argument("--dataset", help="a built dataset folder (default: the one shipped with vccjax)")
    s.add_argument("--out", default="benchmarks/results/search.json", help="result JSON")
    s.set_defaults(fn=cmd_bench_search)
