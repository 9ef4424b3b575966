"""The arm's robustness run: many rollouts of random arm-able concepts (their learned
programs, by default those of the run of record: `robot.sources`) on random scenarios,
32 at a time on MJX, each checked for non-finite state and judged. One JSON
per batch, written when the batch finishes, so an interrupted run resumes where it
stopped; each batch is drawn from its own seed, so a resumed run is the same run."""

from __future__ import annotations

import time
from collections import Counter
from pathlib import Path

import numpy as np

from robot.sources import Programs
from vccjax import files

BATCH = 32
RECORD = {"batch": (int,), "rolled_out": (int,), "non_finite": (int,), "success": (int,), "failures": (dict,),
          "concepts": (list,), "timing": (dict,)}  # a batch's record: what the summary reads


def draw_batch(seed: int, batch: int, programs: Programs, size: int = BATCH) -> list:
    """`size` (name, program, scenario) triples: concepts drawn uniformly from the arm-able
    ones of `programs`; a concept that no scenario of the arm's bodies lets run is drawn again."""
    from robot.choice import arm_able
    from robot.scenario import draw
    from vccjax.errors import SceneError

    rng = np.random.default_rng([seed, batch])
    names = sorted(arm_able(programs.table))
    if not names:
        raise SceneError(f"{programs.source.path or programs.source.kind}: no concept an arm can carry out")
    items, tries = [], 0
    while len(items) < size:
        tries += 1
        if tries > 50 * size:
            raise SceneError(f"batch {batch}: the arm's bodies could stage only {len(items)} of {size} "
                             f"scenarios in {tries - 1} draws")
        name = names[int(rng.integers(len(names)))]
        program = programs.table[name]
        try:
            items.append((name, program, draw(program, int(rng.integers(1 << 30)), max_tries=200)))
        except SceneError:
            continue
    return items


def run_stress(out: str | Path, programs: Programs, rollouts: int = 1000, seed: int = 7, log=print) -> dict:
    """Run (or resume) `rollouts` (rounded up to whole batches) into `out`; returns the
    summary, also written there as summary.json."""
    from tqdm import tqdm

    from robot.judge import tally
    from robot.rollout import Bench
    from robot.suite import finished, read_record, world_sha256, write_record

    from robot.choice import arm_able
    from vccjax.errors import SceneError

    if not arm_able(programs.table):  # said before the progress bar starts
        raise SceneError(f"{programs.source.path or programs.source.kind}: no concept an arm can carry out")
    out = Path(out)
    files.hold(out, "stress folder")  # one writer at a time
    batches = -(-rollouts // BATCH)
    bench = None
    for b in tqdm(range(batches), desc="robot stress", unit="batch"):
        path = out / f"batch-{b:03d}.json"
        if finished(path, RECORD, seed=seed, source=programs.source.label(), world_sha256=world_sha256()):
            continue
        bench = bench or Bench()
        items = draw_batch(seed, b, programs)
        start = time.perf_counter()
        verdicts, info, kept = bench.run_pairs([(p, s) for _, p, s in items], keep=True)
        info["wall_s"] = time.perf_counter() - start
        finite = [q is None or bool(np.isfinite(q).all()) for q in kept]
        record = {"batch": b, "seed": seed, "source": programs.source.label(), "world_sha256": world_sha256(),
                  "timing": info,
                  "concepts": [n for n, _, _ in items], "scenario_seeds": [s.seed for _, _, s in items],
                  "rolled_out": sum(q is not None for q in kept), "non_finite": finite.count(False),
                  **tally(verdicts)}
        write_record(path, record)
        log(f"batch {b}: {record['success']} of {len(items)} carried out, "
            f"{record['non_finite']} non-finite, wall {info['wall_s']:.0f} s")
    rows = [read_record(out / f"batch-{b:03d}.json", RECORD) for b in range(batches)]
    summary = {"seed": seed, "batches": batches, "rollouts": batches * BATCH,
               "rolled_out": sum(r["rolled_out"] for r in rows),
               "non_finite": sum(r["non_finite"] for r in rows),
               "success": sum(r["success"] for r in rows),
               "failures": dict(sum((Counter(r["failures"]) for r in rows), Counter())),
               "concepts": len({c for r in rows for c in r["concepts"]}),
               "wall_s": sum(r["timing"]["wall_s"] for r in rows)}
    files.write_json(out / "summary.json", summary)
    return summary
