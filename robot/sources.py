"""Where the arm's programs come from, and a hash that says which version: the programs a
`vcc induce` run found (what was *learned* on the 546; the default), the user's library
of concepts saved by `vcc learn`, or the shipped reference programs.

A concept `A+B` is a composition: A's program, then B's on the scene A leaves.
"""

from __future__ import annotations

import dataclasses
import hashlib
from pathlib import Path

from vccjax.errors import DataFileError
from vccjax.machine.program import Program, parse

REPOSITORY = Path(__file__).resolve().parents[1]
# explore-compress on the 546 (oracle arguments): what was learned, in a clone of the repository
RUN_OF_RECORD = REPOSITORY / "benchmarks" / "induction" / "o1-oracle-500k"


def shown(path: str | Path) -> str:
    """A folder as records keep it: relative to the repository when inside it (so that a
    record reads the same in every clone), else absolute."""
    full = Path(path).resolve()
    return full.relative_to(REPOSITORY).as_posix() if full.is_relative_to(REPOSITORY) else str(full)


@dataclasses.dataclass(frozen=True)
class Source:
    """One place programs come from: `kind` is "run", "library" or "reference"."""

    kind: str
    path: str | None  # the run's folder, the library's folder, or None for the reference
    sha256: str  # of the run's results, of the saved concept files, or of the reference programs

    def label(self) -> dict:
        return dataclasses.asdict(self)


def induced_programs(run: str | Path) -> dict[str, Program]:
    """{concept: Program} a `vcc induce` run found (its results.jsonl; a later record wins)."""
    path = Path(run) / "results.jsonl"
    if not path.is_file():
        raise DataFileError(f"{path}: missing (give the folder of a `vcc induce` run)")
    from vccjax.records import read_jsonl

    found = {}
    schema = {"concept": (str,), "found": (bool,), "program": (str, None)}
    for k, r in enumerate(read_jsonl(path, schema)):
        if r["found"]:
            if r["program"] is None:
                raise DataFileError(f"{path}: line {k + 1}: a record found has no program")
            try:
                found[r["concept"]] = parse(r["program"])
            except ValueError as e:
                raise DataFileError(f"{path}: line {k + 1}: {e}") from None
    return found


class Programs:
    """Programs by concept name from one source (`--source reference|library|RUN`)."""

    def __init__(self, source: str):
        if source == "reference":
            from vccjax.world.concepts import concept_names, reference_program

            self.table = {c: reference_program(c) for c in concept_names()}
            self.source = Source("reference", None, _digest(self.table))
        elif source == "library":
            from vccjax.world.user_concepts import library_folder, load_concept, saved_concepts

            self.table = {c: parse(load_concept(c)["program"]) for c in saved_concepts()}
            self.source = Source("library", shown(library_folder()), _digest(self.table))
        else:
            self.table = induced_programs(source)
            digest = hashlib.sha256((Path(source) / "results.jsonl").read_bytes()).hexdigest()
            self.source = Source("run", shown(source), digest)

    def __contains__(self, name: str) -> bool:
        return all(part in self.table for part in name.split("+"))

    def of(self, name: str) -> Program | list[Program]:
        """The concept's program; for A+B, [A's, B's]."""
        missing = [c for c in name.split("+") if c not in self.table]
        if missing:
            where = {"run": f"not induced in {self.source.path}", "library": "not in the user's library",
                     "reference": "not a shipped concept"}[self.source.kind]
            raise ValueError(f"{', '.join(missing)}: {where}")
        programs = [self.table[c] for c in name.split("+")]
        return programs[0] if len(programs) == 1 else programs


def _digest(table: dict[str, Program]) -> str:
    text = "\n".join(f"{c}: {table[c].text()}" for c in sorted(table))
    return hashlib.sha256(text.encode()).hexdigest()


def program_sha256(program: Program | list[Program]) -> str:
    """What a scenario record keeps to say which program ran."""
    programs = program if isinstance(program, list) else [program]
    return hashlib.sha256(" + ".join(p.text() for p in programs).encode()).hexdigest()


def programs_of(name: str, induced: str | Path | None = None) -> Program | list[Program]:
    """A concept's program for `vcc robot run`: the reference one (or, for a concept saved
    with `vcc learn --save`, the user's), or the one the `vcc induce` run in `induced` found."""
    from vccjax.world.user_concepts import concept_program

    if induced is not None:
        return Programs(str(induced)).of(name)
    programs = [concept_program(c) for c in name.split("+")]
    return programs[0] if len(programs) == 1 else programs
