"""Run folders' result logs (JSON lines): read them, and mend a last line an interrupt cut.

A log is only ever appended to. A resume must not rewrite what it read: a kill in the
middle of a rewrite would lose the whole run. So a cut last line (the process died while
writing it) is removed by truncating the file just after the last complete line, which
leaves every complete record where it was.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

from vccjax.errors import DataFileError, loads


# A schema maps a field to the types its value may have (`None` for null); an `int`
# field refuses booleans and a `float` field takes ints too, but never NaN or infinity.
# A field named with a trailing `?` may be missing (when present, it has those types).
Schema = dict[str, tuple]


def check_fields(record, schema: Schema, where: str) -> dict:
    """`record` if it is an object whose fields have the schema's types; otherwise a
    DataFileError naming `where` and the first bad field."""
    if not isinstance(record, dict):
        raise DataFileError(f"{where}: a record must be a JSON object, not {type(record).__name__}")
    for field, kinds in schema.items():
        optional = field.endswith("?")
        field = field.rstrip("?")
        if field not in record:
            if optional:
                continue
            raise DataFileError(f"{where}: field '{field}' is missing")
        if not _has_type(record[field], kinds):
            names = "/".join("null" if k is None else k.__name__ for k in kinds)
            raise DataFileError(f"{where}: field '{field}' must be {names}, not {json.dumps(record[field])[:40]}")
    return record


def _has_type(value, kinds: tuple) -> bool:
    for k in kinds:
        if k is None and value is None:
            return True
        if k is bool and isinstance(value, bool):
            return True
        if k is int and isinstance(value, int) and not isinstance(value, bool):
            return True
        if k is float and isinstance(value, (int, float)) and not isinstance(value, bool):
            return math.isfinite(value)
        if k in (str, list, dict) and isinstance(value, k):
            return True
    return False


def read_jsonl(path: Path, schema: Schema | None = None) -> list[dict]:
    """The records of a log; a last line cut by an interrupt is left out (its work is
    redone), any other line that is not JSON, or not of the schema, is an error naming
    its line."""
    records: list[dict] = []
    if not path.exists():
        return records
    if not path.is_file():
        raise DataFileError(f"{path}: not a regular file")
    lines = path.read_bytes().split(b"\n")
    if lines[-1] == b"":
        lines.pop()
    for i, line in enumerate(lines):
        try:
            record = loads(line.decode())
        except (ValueError, RecursionError):  # UnicodeDecodeError is a ValueError too
            if i == len(lines) - 1 and _cut_record(line):
                break
            raise DataFileError(f"{path}: line {i + 1} is not a JSON record we can read") from None
        records.append(check_fields(record, schema or {}, f"{path}: line {i + 1}"))
    return records


def _cut_record(tail: bytes) -> bool:
    """Whether a last line looks like a record whose writing was cut short: the start of
    a JSON object in text. Anything else (binary, another format) is not ours to cut."""
    import codecs

    try:  # a cut may fall inside a character: the decoder keeps its first bytes pending
        text = codecs.getincrementaldecoder("utf-8")().decode(tail, final=False)
    except UnicodeDecodeError:
        return False
    return text.startswith("{") and "\x00" not in text


def append_line(path: Path, record: dict) -> None:
    """Append one record as a whole line, flushed to disk before the work goes on (a
    kill then loses at most the line being written, which a resume drops)."""
    with path.open("a") as f:
        f.write(json.dumps(record, allow_nan=False) + "\n")
        f.flush()
        os.fsync(f.fileno())


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
        if not _cut_record(data[start:]):  # not a record cut short: the user's, kept as it is
            raise DataFileError(f"{path}: its last line is not a record cut by an interrupt") from None
        os.truncate(path, start)
        return
    with path.open("ab") as f:
        f.write(b"\n")
