"""The 546 benchmark concepts and their reference programs (MIT-licensed data, see the file)."""

from __future__ import annotations

import functools
import json
from importlib import resources

from vccjax.errors import DataFileError, ProgramSyntaxError
from vccjax.machine.instructions import REFERENCE_IDS
from vccjax.machine.program import Program, check_loop_syntax

LICENSE = "MIT License, Copyright (c) 2017 Vicarious FPC Inc"


@functools.lru_cache(maxsize=1)
def _raw() -> dict:
    text = resources.files("vccjax.world").joinpath("data/concepts.json").read_text()
    d = json.loads(text)
    if d.get("license") != LICENSE or not isinstance(d.get("concepts"), dict):
        raise DataFileError("vccjax/world/data/concepts.json: not the benchmark concept file")
    if d.get("reference_instruction_ids") != REFERENCE_IDS:
        raise DataFileError("vccjax/world/data/concepts.json: instruction ids differ from docs/vcc.md section 3")
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


DEMO: tuple[str, ...] = (  # a dozen short concepts: `--concepts demo` (all found in under a minute on 2 cores)
    "change_target_obj_to_given_color", "change_target_position_to_given_color", "remove_bottom_obj",
    "remove_given_target_color_objs", "remove_given_target_shape_objs", "remove_left_most_obj",
    "remove_right_most_obj", "remove_top_obj", "remove_given_target_shape_and_color_combo_objs",
    "move_to_bottom_edge", "move_to_right_edge", "move_to_top_edge")


def concept_list(spec: str, available: list[str] | None = None) -> list[str]:
    """Concepts named on a command line: 'all', 'demo' or a comma-separated list. With
    `available` (a dataset's concepts), 'all' means those and every name must be one."""
    names = concept_names() if available is None else list(available)
    if spec == "all":
        return names
    if spec == "demo" and available is None:
        return list(DEMO)
    chosen = list(dict.fromkeys(c.strip() for c in spec.split(",") if c.strip()))  # once each, in order
    if not chosen:
        raise ValueError(f"--concepts {spec!r}: names no concept ('all', 'demo' or a comma-separated list)")
    unknown = [c for c in chosen if c not in names]
    if unknown:
        where = "see `vcc concepts`" if available is None else "not in the dataset's manifest"
        raise ValueError(f"unknown concept(s): {', '.join(unknown)} ({where})")
    return chosen


def read_programs(path) -> dict[str, Program]:
    """Concepts given as `name: program` lines (`#` starts a comment; blank lines are
    skipped), for `vcc dataset build --programs`. Each name once, not one of the 546, and
    each program valid; an error names the file and line."""
    import re
    from pathlib import Path

    from vccjax.machine.program import parse

    path = Path(path)
    if path.exists() and not path.is_file():  # a folder, or a pipe that would block the read
        raise DataFileError(f"{path}: not a regular file; give a programs file")
    try:
        lines = path.read_text().splitlines()
    except FileNotFoundError:
        raise DataFileError(f"{path}: no such programs file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise DataFileError(f"{path}: cannot be read as text ({e})") from None
    shipped = set(concept_names())
    out: dict[str, Program] = {}
    for k, raw in enumerate(lines, 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        name, sep, text = line.partition(":")
        name = name.strip()
        if not sep or not re.match(r"^[a-z][a-z0-9_]{0,63}$", name):
            raise DataFileError(f"{path}:{k}: expected `name: program` with a lower-case name (letters, digits, _)")
        if name in shipped:
            raise DataFileError(f"{path}:{k}: {name!r} is one of the 546 shipped concepts; choose another name")
        if name in out:
            raise DataFileError(f"{path}:{k}: {name!r} is given twice")
        try:
            out[name] = parse(text)
        except ProgramSyntaxError as e:
            raise DataFileError(f"{path}:{k}: {e}") from None
    if not out:
        raise DataFileError(f"{path}: holds no `name: program` line")
    return out
