"""The arm's benchmark: ten concepts (stacking, touching, the pointed location, a
colour-filtered loop, a two-concept composition in the spirit of the paper's lemons and
limes), each in the same number of randomized scenarios. One JSON file per concept,
written when it finishes, so an interrupted run resumes where it stopped."""

from __future__ import annotations

import json
import time
from collections import Counter
from pathlib import Path

SUITE: tuple[str, ...] = (
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


def induced_programs(run: str | Path) -> dict:
    """{concept: Program} a `vcc induce` run found (its results.jsonl; a later record wins)."""
    from vccjax.errors import DataFileError
    from vccjax.machine.program import parse

    path = Path(run) / "results.jsonl"
    if not path.is_file():
        raise DataFileError(f"{path}: missing (give the folder of a `vcc induce` run)")
    found = {}
    for k, line in enumerate(path.read_text().splitlines()):
        try:
            r = json.loads(line)
            if r["found"]:
                found[r["concept"]] = parse(r["program"])
        except (ValueError, KeyError, TypeError) as e:
            raise DataFileError(f"{path}: line {k + 1} is not a result of `vcc induce` ({e})") from None
    return found


def programs_of(name: str, induced: str | Path | None = None):
    """A concept's program: the reference one (or, for a concept learned with `vcc learn
    --save`, the program saved in the user's library), or the one a `vcc induce` run in
    folder `induced` found; for A+B, A's then B's (run on the scene A leaves)."""
    from vccjax.world.user_concepts import concept_program

    parts = name.split("+")
    if induced is None:  # a shipped concept's reference program, or one the user saved
        programs = [concept_program(c) for c in parts]
    else:
        found = induced_programs(induced)
        missing = [c for c in parts if c not in found]
        if missing:
            raise ValueError(f"{', '.join(missing)}: not induced in {induced}")
        programs = [found[c] for c in parts]
    return programs[0] if len(programs) == 1 else programs


def finished(path: Path, **expected) -> bool:
    """Whether `path` holds a record made with these settings (a resume keeps it; one
    made with other settings is redone, not mixed in)."""
    if not path.exists():
        return False
    record = json.loads(path.read_text())
    return all(record.get(k) == v for k, v in expected.items())


def write_record(path: Path, record: dict) -> None:
    """Whole or not at all, if the run is killed while writing (a resume trusts it)."""
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(record, indent=1))
    tmp.replace(path)


def run_suite(out: str | Path, scenarios: int = 32, seed: int = 0, concepts=SUITE, log=print,
              induced: str | Path | None = None) -> dict:
    """Run (or resume) the suite into `out` (reference programs, or those of the `vcc
    induce` run in folder `induced`); returns the summary (also written there)."""
    from tqdm import tqdm

    from robot.judge import tally
    from robot.rollout import Bench, scenarios_for

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    bench = None
    for name in tqdm(concepts, desc="robot suite", unit="concept"):
        path = out / f"{name.replace('<', '').replace('>', '').replace('+', '_then_')}.json"
        source = "reference" if induced is None else f"induced: {induced}"
        if finished(path, scenarios=scenarios, seed=seed, source=source):
            continue
        bench = bench or Bench()
        programs = programs_of(name, induced)
        start = time.perf_counter()
        verdicts, info, _ = bench.run(programs, scenarios_for(programs, scenarios, seed))
        info["wall_s"] = time.perf_counter() - start
        texts = [p.text() for p in (programs if isinstance(programs, list) else [programs])]
        record = {"concept": name, "scenarios": scenarios, "seed": seed, "programs": texts,
                  "source": source, "timing": info,
                  **tally(verdicts)}
        write_record(path, record)
        log(f"{name}: {record['success']} of {scenarios}, wall {info['wall_s']:.0f} s")
    rows = [json.loads(p.read_text()) for p in sorted(out.glob("*.json")) if p.name != "summary.json"]
    total = sum(r["scenarios"] for r in rows)
    summary = {"concepts": len(rows), "rollouts": total, "success": sum(r["success"] for r in rows),
               "failures": dict(sum((Counter(r["failures"]) for r in rows), Counter())),
               "per_concept": {r["concept"]: r["success"] / r["scenarios"] for r in rows}}
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    return summary
