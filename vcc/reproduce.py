"""`vcc bench reproduce`: the paper's induction experiments as rows, each an explore-
compress run of our own beside the paper's figure.

Every row is one `search.induce` run in its own folder (resumable: rerun the same
command and it goes on where it stopped), so long settings run in pieces. Subroutines
on/off needs no run of its own: a run turns subroutines on only once its plain model
has saturated, so what it found before that is what the same run with them off finds
(`found_without_subroutines`). The report reads whatever row folders exist; a row that
was not run says so.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from search.induce import Settings
from vccjax import files

if TYPE_CHECKING:
    from search.cluster import ClusterSearcher
    from search.explore import Searcher

MAIN = "o1-predfix-0.5M"  # the headline run: order 1, predicted + fixation, 0.5M


@dataclasses.dataclass(frozen=True)
class Row:
    name: str
    what: str
    settings: Settings
    paper: str  # the paper's figure for this setting, in its words ("-" where it gives none)
    examples: int = 10  # training pairs per concept (the learning curve takes fewer)
    short_only: bool = False  # the learning curve's concepts (see `concepts_of`)


def _rows() -> list[Row]:
    rows = []
    for budget, tag, paper in ((250_000, "0.25M", "in a figure only (Fig 4E-H)"),
                               (500_000, "0.5M", "524 of 546 at 0.4M"),
                               (1_000_000, "1M", "526 of 546 (525 in the order 0 / order 1 comparison)"),
                               (3_000_000, "3M", "535 of 546 (the programs listed in Fig 2)")):
        rows.append(Row(f"o1-predfix-{tag}", f"order 1, subroutines, predicted arguments + fixation, {tag}",
                        Settings(budget=budget, order=1, args="predicted+fixation", parts=2), paper))
    rows += [
        Row("o1-predicted-0.5M", "order 1, predicted arguments (no fixation guidance), 0.5M",
            Settings(budget=500_000, args="predicted"), "148 of 546 at 0.4M without fixation guidance"),
        Row("o1-uniform-0.5M", "order 1, arguments uniform (no prediction), 0.5M",
            Settings(budget=500_000, args="uniform"), "150 of 546 without argument prediction (1M)"),
        Row("o0-predfix-1M", "order 0, subroutines, predicted arguments + fixation, 1M",
            Settings(budget=1_000_000, order=0, args="predicted+fixation"),
            "7 new with subroutines, 0 without, at 1M (41 without and 61 more with at 3M)"),
    ]
    for k in range(1, 11):  # the learning curve: first-iteration search only, as the paper's
        rows.append(Row(f"examples-{k}", f"{k} training example{'s' * (k > 1)}, iteration 0 only, "
                        "order 1, predicted + fixation, 0.5M",
                        Settings(budget=500_000, args="predicted+fixation", max_iterations=1),
                        "flattens after 5 examples (Fig 5C)", examples=k, short_only=True))
    return rows


ROWS: tuple[Row, ...] = tuple(_rows())
BY_NAME = {r.name: r for r in ROWS}
SHORT = 7  # the learning curve's concepts: reference programs of at most 7 instructions


def select(spec: str) -> list[Row]:
    if spec in ("", "all"):
        return list(ROWS)
    if spec == "none":
        return []
    names = [s.strip() for s in spec.split(",") if s.strip()]
    unknown = [n for n in names if n not in BY_NAME]
    if unknown:
        raise ValueError(f"unknown row(s): {', '.join(unknown)}; rows are: {', '.join(BY_NAME)}")
    return [BY_NAME[n] for n in names]


def concepts_of(row: Row, chosen: Sequence[str]) -> list[str]:
    """The learning curve's concepts are the short ones (the paper's are those its first
    iteration found: a uniform model reaches about this far)."""
    if not row.short_only:
        return list(chosen)
    from vccjax.world.concepts import reference_program

    return [c for c in chosen if len(reference_program(c)) <= SHORT]


def scaled(row: Row, scale: float) -> Settings:
    return dataclasses.replace(row.settings, budget=max(1, int(round(row.settings.budget * scale))))


def folder(runs: Path, row: Row, tag: str, scale: float) -> Path:
    """A row's run folder; another concept set or budget scale is another folder."""
    return runs / (row.name + (f"-{tag}" if tag else "") + (f"-x{scale:g}" if scale != 1 else ""))


def run_row(row: Row, concepts: Sequence[str], out: Path, scale: float, dataset: str | None, width: int,
            progress: bool, searcher: Searcher | ClusterSearcher | None = None) -> dict:
    """One row's run, resumed where it stopped; `searcher` (default: one `Explorer` of
    `width`) may be a `search.cluster.ClusterSearcher`: the same results, each concept's
    search does not depend on where it runs."""
    from search.explore import Explorer
    from search.induce import induce
    from search.run_summary import summary
    from vccjax.world.dataset import dataset_for

    names = concepts_of(row, concepts)
    ds = dataset_for(names, 0, dataset, progress=False)

    def pairs(c: str, split: str):
        got = ds.pairs(c, split)
        return got[: row.examples] if split == "train" else got

    run = induce(names, pairs, out, scaled(row, scale), explorer=searcher or Explorer(width=width),
                 progress=progress, examples_sha256=lambda c: f"{ds.sha256(c)}:first{row.examples}")
    s = {**summary(run, names), "complete": True, "concepts_list": names}
    files.write_json(out / "summary.json", s)
    return s


def finished_otherwise(out: Path, settings: Settings) -> dict | None:
    """The recorded settings of a row folder whose run finished under settings that search
    otherwise than `settings` (a default changed since), else None: such a row is kept as
    it is and reported with its own settings; to rerun it, move the folder aside."""
    from search.induce import Run, same_search

    if not ((out / "run.json").exists() and (out / "summary.json").exists()):
        return None
    recorded = Run.view(out)._meta()["settings"]  # checked: a foreign run.json is one line
    return None if same_search(recorded, dataclasses.asdict(settings)) else recorded


def set_last_pass_aside(out: Path) -> Path | None:
    """For `--redo-last-pass`: a finished row's last-pass records moved to
    `last-pass-K.jsonl` (K the first number free) and its summary dropped, so that running
    the row again searches its last pass anew, with today's code, and the iterations'
    records stay (the same searches). The path they went to, or None where the folder
    holds no finished run with a last pass."""
    from search.induce import read_records

    results, done = out / "results.jsonl", out / "summary.json"
    if not done.exists():
        return None
    files.hold(out)  # no run may write the folder meanwhile
    records = read_records(results)  # checked first: a foreign or corrupt file is refused in one line
    # the records' lines as written (a last line cut by an interrupt, which reading drops, goes)
    lines = [line for line in results.read_text().splitlines() if line.strip()][: len(records)]
    in_pass = [bool(r.get("last_pass")) for r in records]
    moved = [line for line, p in zip(lines, in_pass) if p]
    if not moved:
        return None
    k = next(k for k in range(len(lines) + 1) if not (out / f"last-pass-{k}.jsonl").exists())
    aside = out / f"last-pass-{k}.jsonl"
    files.write_whole(aside, "\n".join(moved) + "\n")
    done.unlink()  # before the records change: cut here, the row resumes as it was
    files.write_whole(results, "".join(line + "\n" for line, p in zip(lines, in_pass) if not p))
    return aside


def read_row(path: Path) -> dict | None:
    """A row folder's figures: its summary when the run finished, else what its records say
    so far (marked partial). None when the folder holds no run."""
    from search.induce import Run
    from search.run_summary import summary

    if not (path / "run.json").exists():
        return None
    run = Run.view(path)
    info = json.loads((path / "run.json").read_text())
    done = path / "summary.json"
    if done.exists():
        s = {"complete": True, **json.loads(done.read_text())}  # written when a run ends
    else:
        s = {**summary(run, sorted(info.get("examples_sha256", {}))), "complete": False}
    predictor = info.get("predictor_sha256")
    return {**s, "row": row_of(path.name), "lengths_per_iteration": lengths(run.records),
            "settings": info.get("settings", {}),
            **({"predictor_sha256": predictor} if predictor else {})}


def row_of(folder_name: str) -> str:
    """The row a run folder holds (its name starts with the row's; the longest match wins)."""
    return next((r for r in sorted(BY_NAME, key=len, reverse=True) if folder_name.startswith(r)), folder_name)


def concept_tag(spec: str, names: Sequence[str]) -> str:
    """A folder suffix naming the concept set: none for all 546; two lists of the same
    length get different suffixes, so their runs never mix."""
    if spec == "all":
        return ""
    if spec == "demo":
        return "demo"
    return f"{len(names)}concepts-{hashlib.sha256(','.join(sorted(names)).encode()).hexdigest()[:6]}"


def lengths(records: Sequence[dict]) -> dict[str, dict[int, int]]:
    """Programs found in each iteration by length (atomic instructions)."""
    out: dict[str, Counter] = {}
    for r in records:
        if r.get("found") and r.get("program"):
            n = len([s for s in r["program"].replace("\n", ";").split(";") if s.strip()])
            out.setdefault(str(r["iteration"]), Counter())[n] += 1
    return {it: dict(sorted(c.items())) for it, c in sorted(out.items(), key=lambda x: int(x[0]))}
