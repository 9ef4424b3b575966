"""Result logs: a resume reads them and mends a cut last line in place; it never
rewrites the records it read (a kill during a rewrite once emptied a finished run)."""

from __future__ import annotations

import json
import os

import pytest

from vccjax.errors import DataFileError, VCCError
from vccjax.records import drop_cut_tail, read_jsonl

LINES = [{"concept": f"c{k}", "found": k % 2 == 0, "iteration": 0, "program": "scene_parse" if k % 2 == 0 else None,
          "dl": 1.5, "nodes": k, "programs_run": k, "seconds": 0.1} for k in range(5)]


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
    last = {**LINES[0], "concept": "c5"}
    path = _log(tmp_path, json.dumps(last).encode())
    drop_cut_tail(path)
    assert read_jsonl(path) == [*LINES, last] and path.read_bytes().endswith(b"}\n")


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
    with pytest.raises(DataFileError, match="line 3 is not a JSON record"):
        read_jsonl(path)


def test_an_induce_run_resumed_keeps_its_file_and_drops_only_the_cut_line(tmp_path):
    from search.induce import Run, Settings

    run = tmp_path / "run"
    Run(run, Settings())  # makes run.json
    path = _log(run, b'{"concept": "cu')
    inode = os.stat(path).st_ino
    r = Run(run, Settings())
    assert r.records == LINES and os.stat(path).st_ino == inode and read_jsonl(path) == LINES
    cut = path.read_bytes()  # left as it is until the run goes on: a resume refused later changes nothing
    assert not cut.endswith(b"\n")
    r.append({"concept": "next", "iteration": 0, "found": False, "program": None})
    assert os.stat(path).st_ino == inode and path.read_bytes().startswith(cut[:cut.rfind(b"\n") + 1])
    assert [x["concept"] for x in read_jsonl(path)] == [x["concept"] for x in LINES] + ["next"]


@pytest.mark.parametrize("line, field", [
    ("[1, 2, 3]", "a JSON object"),
    ('{"concept": "c", "found": "no", "iteration": 0, "program": null, "dl": null, "nodes": 1, '
     '"programs_run": 1, "seconds": 0.1}', "'found' must be bool"),
    ('{"concept": "c", "found": true, "iteration": "0", "program": "scene_parse", "dl": 1.0, "nodes": 1, '
     '"programs_run": 1, "seconds": 0.1}', "'iteration' must be int"),
    ('{"concept": "c", "found": true, "iteration": 0, "program": "scene_parse", "dl": NaN, "nodes": 1, '
     '"programs_run": 1, "seconds": 0.1}', "is not a JSON record"),  # NaN is not JSON
    ('{"concept": "c", "found": true, "iteration": 0, "program": "scene_parse", "dl": "1", "nodes": 1, '
     '"programs_run": 1, "seconds": 0.1}', "'dl' must be float/null"),
    ('{"concept": "c", "iteration": 0}', "'found' is missing"),
])
def test_a_record_of_the_wrong_shape_is_refused_by_line_and_field(tmp_path, line, field):
    from search.induce import read_records

    path = _log(tmp_path, line.encode() + b"\n" + json.dumps(LINES[0]).encode() + b"\n")
    with pytest.raises(DataFileError, match="line 6") as e:
        read_records(path)
    assert field in str(e.value)


def test_a_second_writer_of_a_run_folder_is_refused_naming_the_first(tmp_path):
    """The lock is held by another process (a subprocess that holds it and waits)."""
    import subprocess
    import sys

    from search.induce import Run, Settings

    run = tmp_path / "run"
    holder = subprocess.Popen([sys.executable, "-c", (
        "import sys, time; from vccjax import files; files.hold(sys.argv[1]); print('held', flush=True); "
        "time.sleep(60)"), str(run)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(VCCError, match=f"in use by pid {holder.pid}"):
            Run(run, Settings())
        assert not (run / "run.json").exists()  # refused before it wrote anything
    finally:
        holder.kill()
        holder.wait()
    Run(run, Settings())  # the holder is gone: its lock went with it
    assert (run / "run.json").exists()


def test_a_last_line_that_is_no_cut_record_is_kept_and_refused(tmp_path):
    """Binary or foreign bytes at the end are the user's: a resume refuses them rather
    than cutting them away."""
    path = _log(tmp_path, bytes(range(256)) * 4)
    size = path.stat().st_size
    with pytest.raises(DataFileError, match="line 6"):
        read_jsonl(path)
    with pytest.raises(DataFileError, match="not a record cut"):
        drop_cut_tail(path)
    assert path.stat().st_size == size


def test_a_cut_inside_a_character_is_still_a_cut_record(tmp_path):
    tail = json.dumps({"concept": "é"}, ensure_ascii=False).encode()[:14]  # ends inside the é
    path = _log(tmp_path, tail)
    assert read_jsonl(path) == LINES
    drop_cut_tail(path)
    assert read_jsonl(path) == LINES and path.read_bytes().endswith(b"\n")
