"""The arm's benchmark: concepts carried out from their *learned* programs (by default
those of the run of record; `robot.sources`), each in the same number of randomized
scenarios, judged against the scene truly on the table (`robot.judge`, `robot.truth`).

One JSON file per concept, written when its batch finishes, holding one record per
scenario (seed, verdict, parse check) and the program's source, text and hash; an
interrupted run resumes where it stopped, and a record made with another program,
source, seed, scenario count or world (`world_sha256`) is redone, not mixed in.
Scenarios of several concepts share one MJX batch. `shard` splits the concepts between
processes that write into the same folder (each its own files), so that two single-core
processes use two cores.
"""

from __future__ import annotations

import json
import time
from collections import Counter
from collections.abc import Callable, Sequence
from pathlib import Path

from robot.sources import Programs, program_sha256

TEN: tuple[str, ...] = (  # the first suite: stacking, touching, the pointer, a colour loop, a composition
    "stack_in_place_horizontal_left",
    "stack_object_upper_left_corner_vertically",
    "make_the_green_obj_touch_the_red_obj",
    "make_left_most_obj_touch_the_next_obj",
    "move_bottom_to_pointed",
    "move_green_to_pointed_location_and_red_to_left",
    "move_all_yellow_left",
    "move_all_yellow_down_AND_move_all_green_up",
    "move_green_to_right_bottom_corner",
    "move_all_yellow_left+move_green_to_right_bottom_corner",  # composition: yellow aside, the green one away
)
BATCH = 32  # scenarios rolled out at once (whole concepts)
XLA_FLAG = "--xla_cpu_use_fusion_emitters=false"  # batched MJX 14x faster on CPU (docs/robot.md, "MJX on CPU")


def file_of(out: Path, name: str) -> Path:
    return out / f"{name.replace('<', '').replace('>', '').replace('+', '_then_')}.json"


def read_record(path: Path, schema: dict | None = None) -> dict:
    """A concept's record (or another of this schema), refused by name when it is not one."""
    from vccjax.errors import DataFileError, read_json
    from vccjax.records import check_fields

    schema = {"concept": (str,), "records": (list,)} if schema is None else schema
    return check_fields(read_json(path, DataFileError, "missing"), schema, str(path))


def finished(path: Path, schema: dict | None = None, **expected) -> bool:
    """Whether `path` holds a record (of `schema`, as `read_record`) made with these
    settings (a resume keeps it; one made with other settings is redone, not mixed in).
    A source matches on its kind and folder: its hash is kept as provenance, and a run or
    library that gained other concepts leaves this one's record good (`program_sha256`
    says what ran)."""
    if not path.exists():
        return False
    record = read_record(path, schema)
    for k, v in expected.items():
        got = record.get(k)
        if k == "source" and isinstance(got, dict):
            got, v = (got.get("kind"), got.get("path")), (v.get("kind"), v.get("path"))
        if got != v:
            return False
    return True


def write_record(path: Path, record: dict) -> None:
    """Whole or not at all, if the run is killed while writing (a resume trusts it); each
    process through its own temporary file, since shards share the summary."""
    from vccjax import files

    files.write_json(path, record)


def world_sha256() -> str:
    """The arm's world (model, bodies, textures): a record made in another world is redone."""
    import hashlib

    from robot.mjcf import scene_xml

    return hashlib.sha256(scene_xml().encode()).hexdigest()


def _settings(programs: Programs, name: str, scenarios: int, seed: int) -> dict:
    """What a record must have been made with to be kept on a resume."""
    return {"scenarios": scenarios, "seed": seed, "source": programs.source.label(),
            "program_sha256": program_sha256(programs.of(name)), "world_sha256": world_sha256()}


class SuiteWorker:
    """One MJX rollout engine in its own process (a Ray actor, `vccjax.actor_pool`), on
    one core (batched MJX on CPU is as fast on one: docs/robot.md, "MJX on CPU")."""

    def __init__(self, slot: int):
        from vccjax import runtime
        from vccjax.actor_pool import pin

        pin(slot, 1)
        runtime.prepare(xla_flags=[XLA_FLAG])
        from robot.rollout import Bench

        self.bench = Bench()

    def pid(self) -> int:
        import os

        return os.getpid()

    def roll(self, pairs: list) -> tuple[list, dict]:
        start = time.perf_counter()
        verdicts, info, _ = self.bench.run_pairs(pairs, pad_to=BATCH)
        return verdicts, {**info, "wall_s": time.perf_counter() - start}


def run_suite(out: str | Path, programs: Programs, concepts: Sequence[str], scenarios: int = 8, seed: int = 0,
              log: Callable[[str], None] = print, shard: tuple[int, int] = (0, 1), pool=None) -> dict:
    """Run (or resume) `concepts` (this shard's share) into `out`; returns the summary
    of every concept of `concepts` recorded there (also written as summary.json). With a
    `pool` (`vccjax.actor_pool.ActorPool` of `SuiteWorker`), the batches are rolled out
    on its workers and this process writes every record as its batch comes back."""
    from tqdm import tqdm

    from robot.judge import Verdict
    from robot.scenario import draw
    from vccjax.errors import SceneError

    from vccjax import files

    out = Path(out)
    files.hold(out, "suite folder" if shard == (0, 1) else f"suite shard {shard[0]}/{shard[1]}",
               name=".vcc.lock" if shard == (0, 1) else f".vcc-shard-{shard[0]}-of-{shard[1]}.lock")

    def settings(name: str) -> dict:
        return _settings(programs, name, scenarios, seed)

    concepts = list(dict.fromkeys(concepts))  # a name given twice runs once
    mine = concepts[shard[0]::shard[1]]
    todo = [c for c in mine if not finished(file_of(out, c), **settings(c))]
    batches = []  # (the concepts, their drawn scenarios, verdicts known without a rollout)
    while todo:
        group, items, staged = [], [], {}
        while todo and (not group or len(items) + scenarios <= BATCH):
            name = todo.pop(0)
            program = programs.of(name)
            group.append(name)
            for k in range(scenarios):
                s = seed * 100_003 + k
                try:
                    items.append((name, program, draw(program, s)))
                except SceneError as e:
                    staged.setdefault(name, {})[s] = Verdict(False, "no scenario", str(e), float("nan"), s)
        batches.append((group, items, staged))
    bar = tqdm(total=sum(len(g) for g, _, _ in batches), desc="robot suite", unit="concept")

    def record(batch: int, verdicts: list, info: dict) -> None:
        group, items, staged = batches[batch]
        for (name, _, sc), v in zip(items, verdicts, strict=True):
            staged.setdefault(name, {})[sc.seed] = v
        for name in group:
            runs = [staged[name][s] for s in sorted(staged[name])]
            program = programs.of(name)
            texts = [p.text() for p in (program if isinstance(program, list) else [program])]
            rec = {"concept": name, **settings(name), "programs": texts, "batch": {"concepts": group, **info},
                   "success": sum(v.success for v in runs),
                   "failures": dict(Counter(v.cause for v in runs if not v.success)),
                   "records": [v.record() for v in runs]}
            write_record(file_of(out, name), rec)
            log(f"{name}: {rec['success']} of {scenarios}")
            bar.update(1)
        summarise(out, programs, concepts, scenarios, seed)  # a partial run reads as far as it went

    rolled = [b for b, (_, items, _) in enumerate(batches) if items]
    for b in set(range(len(batches))) - set(rolled):
        record(b, [], {"wall_s": 0.0})  # every scenario refused before a rollout
    if pool is not None:
        pool.map("roll", [([(p, sc) for _, p, sc in batches[b][1]],) for b in rolled],
                 lambda i, got: record(rolled[i], *got))
    else:
        bench = None
        for b in rolled:
            if bench is None:
                from robot.rollout import Bench

                bench = Bench()
            start = time.perf_counter()
            verdicts, info, _ = bench.run_pairs([(p, sc) for _, p, sc in batches[b][1]], pad_to=BATCH)
            record(b, verdicts, {**info, "wall_s": time.perf_counter() - start})
    bar.close()
    return summarise(out, programs, concepts, scenarios, seed)


def summarise(out: Path, programs: Programs, concepts: Sequence[str], scenarios: int, seed: int) -> dict:
    """Successes, failures by cause, parse accuracy and per-concept rates over the
    concepts recorded in `out` with these settings (summary.json)."""
    rows = []
    for name in concepts:
        path = file_of(out, name)
        if finished(path, **_settings(programs, name, scenarios, seed)):
            rows.append(read_record(path))
    from robot.choice import STRATA, length, not_arm_able

    records = [r for row in rows for r in row["records"]]
    parsed = [r["parse"] for r in records if r.get("parse")]
    strata = {}
    for lo, hi in STRATA:
        these = [row for row in rows if lo <= length(programs.of(row["concept"])) <= hi]
        strata[f"{lo}-{hi}" if hi < 10**6 else f"{lo}+"] = {
            "chosen": sum(lo <= length(programs.of(c)) <= hi for c in concepts), "recorded": len(these),
            "rollouts": sum(row["scenarios"] for row in these), "success": sum(row["success"] for row in these)}
    excluded = Counter(why for p in programs.table.values() if (why := not_arm_able(p)))
    summary = {"source": programs.source.label(), "scenarios": scenarios, "seed": seed,
               "source_programs": len(programs.table), "arm_able": len(programs.table) - sum(excluded.values()),
               "not_arm_able": dict(excluded), "by_length": strata,
               "concepts": len(rows), "of": len(concepts), "rollouts": len(records),
               "success": sum(r["success"] for r in records),
               "failures": dict(sum((Counter(row["failures"]) for row in rows), Counter())),
               "parse": {"scenes": len(parsed), "scenes_exact": sum(p["exact"] for p in parsed),
                         "objects": sum(p["objects"] for p in parsed),
                         "objects_exact": sum(p["exact_objects"] for p in parsed),
                         "largest_centre_error_m": max((p["centre_error_m"] for p in parsed), default=0.0)},
               "per_concept": {row["concept"]: row["success"] / row["scenarios"] for row in rows}}
    write_record(out / "summary.json", summary)
    return summary
