"""`map_with_progress`: jobs in spawned workers come back in order, a job's error reaches
the caller, and the workers leave Ctrl-C to the parent (which stops them at once)."""

from __future__ import annotations

import signal

import pytest

from vccjax.parallel import map_with_progress


def _square(x: int) -> int:
    if x < 0:
        raise ValueError(f"negative job {x}")
    return x * x


def _ctrl_c_handler(_: int) -> bool:
    return signal.getsignal(signal.SIGINT) == signal.SIG_IGN


def test_jobs_come_back_in_order_in_workers_and_in_process():
    jobs = list(range(11))
    assert map_with_progress(_square, jobs, 2, 3, "t", False) == [x * x for x in jobs]
    assert map_with_progress(_square, jobs, 0, 3, "t", False) == [x * x for x in jobs]


def test_a_jobs_error_reaches_the_caller():
    with pytest.raises(ValueError, match="negative job -1"):
        map_with_progress(_square, [1, 2, -1, 3], 2, 1, "t", False)


def test_workers_ignore_ctrl_c_and_the_parent_keeps_it():
    assert map_with_progress(_ctrl_c_handler, [0, 1], 2, 1, "t", False) == [True, True]
    assert signal.getsignal(signal.SIGINT) != signal.SIG_IGN
