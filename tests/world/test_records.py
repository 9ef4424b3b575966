"""Result logs: a resume reads them and mends a cut last line in place; it never
rewrites the records it read (a kill during a rewrite once emptied a finished run)."""

from __future__ import annotations

import json
import os

import pytest

from vccjax.errors import DataFileError
from vccjax.records import drop_cut_tail, read_jsonl

LINES = [{"concept": f"c{k}", "found": k % 2 == 0} for k in range(5)]


def _log(tmp_path, tail: bytes = b"") -> os.PathLike:
    path = tmp_path / "results.jsonl"
    path.write_bytes(b"".join(json.dumps(r).encode() + b"\n" for r in LINES) + tail)
    return path


def test_a_cut_last_line_is_left_out_and_cut_away_in_place(tmp_path):
    path = _log(tmp_path, b'{"concept": "c5", "fou')
    whole = path.read_bytes()[: -len(b'{"concept": "c5", "fou')]
    inode = os.stat(path).st_ino
    assert read_jsonl(path) == LINES
    drop_cut_tail(path)
    assert path.read_bytes() == whole and os.stat(path).st_ino == inode  # the same file, truncated


def test_a_complete_last_line_without_its_newline_is_kept(tmp_path):
    path = _log(tmp_path, json.dumps({"concept": "c5"}).encode())
    drop_cut_tail(path)
    assert read_jsonl(path) == [*LINES, {"concept": "c5"}] and path.read_bytes().endswith(b"}\n")


def test_a_kill_while_mending_loses_no_record(tmp_path, monkeypatch):
    """The kill is injected where the mend writes: every complete record is still there,
    and the next resume mends it."""
    path = _log(tmp_path, b'{"cut')

    def killed(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "truncate", killed)
    with pytest.raises(KeyboardInterrupt):
        drop_cut_tail(path)
    assert read_jsonl(path) == LINES
    monkeypatch.undo()
    drop_cut_tail(path)
    assert read_jsonl(path) == LINES and path.read_bytes().endswith(b"\n")


def test_a_bad_line_before_the_last_is_an_error_naming_it(tmp_path):
    path = _log(tmp_path)
    text = path.read_text().splitlines()
    text[2] = "{not json"
    path.write_text("\n".join(text) + "\n")
    with pytest.raises(DataFileError, match="line 3 is not JSON"):
        read_jsonl(path)


def test_an_induce_run_resumed_keeps_its_file_and_drops_only_the_cut_line(tmp_path):
    from search.induce import Run, Settings

    run = tmp_path / "run"
    Run(run, Settings())  # makes run.json
    path = _log(run, b'{"concept": "cu')
    inode = os.stat(path).st_ino
    r = Run(run, Settings())
    assert r.records == LINES and os.stat(path).st_ino == inode and read_jsonl(path) == LINES
    assert path.read_bytes().endswith(b"\n")
