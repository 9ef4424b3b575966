"""A run killed at any write of a resume, again and again, loses and doubles nothing.

Each resume is a forked process that opens the run folder (`search.induce.Run`: it
rewrites run.json and mends the log) and appends records; it kills itself with SIGKILL
in the middle of its k-th write (k drawn at random), after writing a random part of
that write's bytes, as a power cut or `kill -9` would. A last resume runs to the end.
"""

from __future__ import annotations

import json
import os
import signal
import time
import warnings

import numpy as np
import pytest

CONCEPTS = [f"c{k:03d}" for k in range(40)]


def _record(concept: str) -> dict:
    return {"concept": concept, "found": True, "iteration": 0, "program": "scene_parse", "dl": 1.0,
            "nodes": 1, "programs_run": 1, "seconds": 0.0}


def _resume(folder, kill_at: int | None, rng: np.random.Generator) -> None:
    """In the child: resume the run, dying within write number `kill_at`."""
    from search import induce
    from vccjax import files

    writes = {"n": 0}
    real_whole, real_append = files.write_whole, induce.append_line

    def die_partway(path, data: bytes, mode: str) -> None:
        with open(path, mode) as f:
            f.write(data[: int(rng.integers(0, len(data) + 1))])
        os.kill(os.getpid(), signal.SIGKILL)

    def whole(path, data):
        writes["n"] += 1
        if writes["n"] == kill_at:  # cut while writing the temporary file, before its rename
            die_partway(files._temporary(files.Path(path)), data.encode() if isinstance(data, str) else data, "wb")
        real_whole(path, data)

    def append(path, record):
        writes["n"] += 1
        if writes["n"] == kill_at:
            die_partway(path, (json.dumps(record) + "\n").encode(), "ab")
        real_append(path, record)

    files.write_whole, induce.append_line = whole, append
    run = induce.Run(folder, induce.Settings())
    done = {r["concept"] for r in run.records}
    for c in CONCEPTS:
        if c not in done:
            run.append(_record(c))


def _fork_resume(folder, kill_at: int | None, seed: int) -> int:
    """Fork (a fresh interpreter would spend seconds importing JAX for each resume); the
    child touches no JAX, only files."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # JAX's warning about fork and its threads
        pid = os.fork()
    if pid == 0:  # the child never returns into pytest
        code = 0
        try:
            _resume(folder, kill_at, np.random.default_rng(seed))
        except BaseException:
            code = 1
        os._exit(code)
    for _ in range(600):  # a forked child of a threaded parent could deadlock: never wait forever
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return status
        time.sleep(0.1)
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)
    raise AssertionError("a resume did not end within 60 s")


@pytest.mark.parametrize("kills", [8, pytest.param(20, marks=pytest.mark.slow)])
def test_kills_at_random_writes_of_resumes_lose_and_double_nothing(tmp_path, kills):
    from search.induce import read_records

    folder = tmp_path / "run"
    rng = np.random.default_rng(kills)
    before: list[dict] = []
    died = 0
    for k in range(kills):
        left = len(CONCEPTS) - len(before)
        status = _fork_resume(folder, int(rng.integers(1, left + 2)), seed=k)  # +1: run.json's rewrite
        died += os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL
        now = read_records(folder / "results.jsonl")
        assert now[: len(before)] == before  # nothing that was whole is lost
        assert len({r["concept"] for r in now}) == len(now)  # nor doubled
        before = now
    assert died == kills  # every resume was killed (none had finished the run)
    assert os.WEXITSTATUS(_fork_resume(folder, None, seed=kills)) == 0
    final = read_records(folder / "results.jsonl")
    assert [r["concept"] for r in final] == CONCEPTS
    assert not list(folder.glob(".*tmp*"))  # the killed writers' temporaries were cleared
    info = json.loads((folder / "run.json").read_text())
    assert 1 <= len(info["sessions"]) <= kills + 1
