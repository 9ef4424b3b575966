"""The 546 benchmark concepts and their reference programs (MIT-licensed data, see the file)."""

from __future__ import annotations

import functools
import json
from importlib import resources

from vccjax.errors import DataFileError, ProgramSyntaxError
from vccjax.instructions import REFERENCE_IDS
from vccjax.program import Program, check_loop_syntax

LICENSE = "MIT License, Copyright (c) 2017 Vicarious FPC Inc"


@functools.lru_cache(maxsize=1)
def _raw() -> dict:
    text = resources.files("vccjax").joinpath("data/concepts.json").read_text()
    d = json.loads(text)
    if d.get("license") != LICENSE or not isinstance(d.get("concepts"), dict):
        raise DataFileError("vccjax/data/concepts.json: not the benchmark concept file")
    if d.get("reference_instruction_ids") != REFERENCE_IDS:
        raise DataFileError("vccjax/data/concepts.json: instruction ids differ from the spec's table")
    return d


def concept_names() -> list[str]:
    """All concept names, in the file's order."""
    return list(_raw()["concepts"])


@functools.lru_cache(maxsize=None)
def reference_program(name: str) -> Program:
    """The reference program that defines a concept."""
    concepts = _raw()["concepts"]
    if name not in concepts:
        close = [c for c in concepts if name.lower() in c.lower()][:5]
        hint = f"; did you mean {', '.join(close)}?" if close else ""
        raise KeyError(f"unknown concept {name!r}{hint}")
    try:
        program = Program.from_steps(concepts[name])
        check_loop_syntax(program)
    except ProgramSyntaxError as e:
        raise DataFileError(f"concept {name}: {e}") from None
    return program


def all_concepts() -> dict[str, Program]:
    return {name: reference_program(name) for name in concept_names()}
