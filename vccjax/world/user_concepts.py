"""The user's concept library: concepts learned with `vcc learn --save`, one JSON file
each in a folder (`$VCC_LIBRARY`, default `$XDG_DATA_HOME/vccjax/concepts`, that is
`~/.local/share/vccjax/concepts`), so that `vcc run`, `vcc trace` and `vcc robot run`
find them by name beside the 546 shipped concepts.

A file holds the learned program's text (subroutines expanded) and what learning it
reported, plus the sha256 of that content: an edited or foreign file is refused by name.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from vccjax.errors import DataFileError, VCCError, read_json
from vccjax.records import check_fields
from vccjax.machine.program import Program, parse
from vccjax.sealed import intact, seal, write_whole

FORMAT = "vccjax-concept"
VERSION = 1
NAME = re.compile(r"^[a-z][a-z0-9_]{0,63}$")


def library_folder() -> Path:
    """Where saved concepts live: `$VCC_LIBRARY`, else under the user's data directory."""
    if os.environ.get("VCC_LIBRARY"):
        return Path(os.environ["VCC_LIBRARY"]).expanduser()
    data = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(data) / "vccjax" / "concepts"


def check_name(name: str) -> str:
    """A concept name a user may save: lower-case letters, digits and `_`, not one of the
    546 shipped concepts (those names are taken)."""
    from vccjax.world.concepts import concept_names

    if not NAME.match(name):
        raise VCCError(f"--name {name!r}: use lower-case letters, digits and _ (a letter first, at most 64)")
    if name in concept_names():
        raise VCCError(f"--name {name!r}: a shipped concept has this name; choose another")
    return name


def save_concept(name: str, learned: dict, folder: Path | None = None) -> Path:
    """Write `learned` (what `vcc learn` wrote to concept.json) as concept `name`; an
    existing concept of that name is replaced whole."""
    check_name(name)
    parse(learned["program"])  # never store a program that does not parse
    folder = folder or library_folder()
    folder.mkdir(parents=True, exist_ok=True)
    content = {"format": FORMAT, "version": VERSION, "name": name, **{k: v for k, v in learned.items()
                                                                      if k not in ("format", "version", "name")}}
    path = folder / f"{name}.json"
    write_whole(path, seal(content))
    return path


def load_concept(name: str, folder: Path | None = None) -> dict:
    """A saved concept's content, verified."""
    folder = folder or library_folder()
    path = folder / f"{name}.json"
    if not NAME.match(name) or not path.is_file():
        raise KeyError(f"unknown concept {name!r}: not one of the 546 and not in your library {folder}")
    content = read_json(path, DataFileError, "missing")
    if not isinstance(content, dict) or content.get("format") != FORMAT:
        raise DataFileError(f"{path}: not a {FORMAT} file")
    if content.get("version") != VERSION:
        raise DataFileError(f"{path}: concept format version {content.get('version')}, this vccjax reads {VERSION}")
    if not intact(content) or content.get("name") != name:
        raise DataFileError(f"{path}: content sha256 mismatch (edited or corrupt)")
    check_fields(content, {"program": (str,)}, str(path))
    try:
        parse(content["program"])
    except ValueError as e:
        raise DataFileError(f"{path}: its program does not parse ({e})") from None
    return content


def saved_concepts(folder: Path | None = None) -> list[str]:
    folder = folder or library_folder()
    return sorted(p.stem for p in folder.glob("*.json") if NAME.match(p.stem)) if folder.is_dir() else []


def concept_program(name: str) -> Program:
    """The program a concept name stands for: a shipped concept's reference program, or
    the program the user's library holds under that name."""
    from vccjax.world.concepts import concept_names, reference_program

    if name in concept_names():
        return reference_program(name)
    return parse(load_concept(name)["program"])
