"""A run's figures from its folder: how many concepts were found and how fast, per
iteration and in the last pass (`summary.json`, and the report's rows)."""

from __future__ import annotations

import json
from collections.abc import Sequence

from search.induce import Run


def wall_seconds(run: Run) -> float:
    """The run's wall time over all its sessions: each from its start to its last record
    (a session killed later loses only the time after that record)."""
    starts = json.loads((run.out / "run.json").read_text()).get("sessions", [])
    total = 0.0
    for k, start in enumerate(starts):
        ats = [r["at"] for r in run.records if r.get("session") == k and "at" in r]
        total += max(ats) - start if ats else 0.0
    return total


def summary(run: Run, concepts: Sequence[str]) -> dict:
    recs = [r for r in run.records if r["concept"] in set(concepts)]
    found = {r["concept"]: r for r in recs if r["found"]}
    spent = sum(r["seconds"] for r in recs)  # each concept's share of the lockstep rounds
    secs = spent - sum(r.get("compile_seconds", 0.0) for r in recs)
    covered = sum(r["covered"] for r in recs)
    exact = sum(1 for r in found.values() if r["test_correct"] == r["test_total"])
    return {
        "concepts": len(set(concepts)), "found": len(found), "exact_on_all_test_pairs": exact,
        # milliseconds kept: a short run whose steps were compiled earlier in the process
        # searches for well under 0.05 s, which must not read as no time at all
        "wall_seconds": round(wall_seconds(run), 3),
        "search_seconds": round(secs, 3), "compile_seconds": round(spent - secs, 3),
        "programs_covered": covered,
        "programs_run": sum(r["programs_run"] for r in recs), "nodes": sum(r["nodes"] for r in recs),
        "programs_per_second": round(covered / secs) if secs else None,
        "programs_run_per_second": round(sum(r["programs_run"] for r in recs) / secs) if secs else None,
        # what the same run with subroutines off finds: it stops where this one turns them on
        "found_without_subroutines": sum(1 for r in found.values()
                                         if not r.get("subroutines") and not r.get("last_pass")),
        # the last pass after the iterations (`search.parts_pass`): found there, and in parts
        "found_in_last_pass": sum(1 for r in found.values() if r.get("last_pass")),
        "found_in_parts": sum(1 for r in found.values() if r.get("parts")),
        "per_iteration": {
            it: sum(1 for r in recs if r["iteration"] == it and r["found"])
            for it in sorted({r["iteration"] for r in recs})
        },
    }
