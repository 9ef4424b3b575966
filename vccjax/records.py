"""Run folders' result logs (JSON lines): read them, and mend a last line an interrupt cut.

A log is only ever appended to. A resume must not rewrite what it read: a kill in the
middle of a rewrite would lose the whole run. So a cut last line (the process died while
writing it) is removed by truncating the file just after the last complete line, which
leaves every complete record where it was.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from vccjax.errors import DataFileError


def read_jsonl(path: Path) -> list[dict]:
    """The records of a log; a last line cut by an interrupt is left out (its work is
    redone), any other line that is not JSON is an error naming it."""
    records: list[dict] = []
    if not path.exists():
        return records
    lines = path.read_text().splitlines()
    for i, line in enumerate(lines):
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            if i == len(lines) - 1:
                break
            raise DataFileError(f"{path}: line {i + 1} is not JSON") from None
    return records


def drop_cut_tail(path: Path) -> None:
    """Remove a last line cut by an interrupt, in place (a truncation, not a rewrite); a
    complete last line that only lacks its newline gets one."""
    if not path.exists():
        return
    data = path.read_bytes()
    if not data or data.endswith(b"\n"):
        return
    start = data.rfind(b"\n") + 1
    try:
        json.loads(data[start:])
    except ValueError:
        os.truncate(path, start)
        return
    with path.open("ab") as f:
        f.write(b"\n")
