"""Many concepts' searches in lockstep, so that they share device calls.

Each concept's depth-first search (`search.dfs.depth_first`) is a coroutine that asks
for its next slice of children to be run. One round collects the pending request of
every active search and answers them all with one `Backend.apply_many`, which steps
the children of all of them together, grouped by instruction: a device call then holds
the programs of many concepts, and its fixed cost is paid once per round instead of
once per concept. A concept's result does not depend on which others share its rounds.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Generator, Sequence

import numpy as np

from search.backend import Backend, Reply, Request
from search.chain import Chain
from search.dfs import Alternatives, depth_first
from search.result import Outcome, Result, result_of
from search.task import Task


@dataclasses.dataclass
class _Running:
    """A search taking part in the rounds."""

    search: Generator[Request, Reply, Outcome]
    request: Request  # what it waits for
    seconds: float  # its share of the rounds so far, plus its own host time
    compile_seconds: float  # its share of the rounds' compile time


def search_in_lockstep(backend: Backend, jobs: Sequence[tuple[Chain, Task]], budget: int,
                       done: Callable[[int, Result], None], *, width: int, chunk: int, slice_size: int,
                       alternatives: Alternatives | None = None) -> None:
    """Explore every (chain, task) job, `width` at a time in lockstep; `done(index,
    result)` is called as each finishes (in finishing order). A job's `seconds` and
    `compile_seconds` are its share, by rows stepped, of the rounds it took part in.

    Jobs start in order as others finish; searches running together have the same
    number of examples (a batch's rows are programs x examples), so a job with another
    count waits until the running ones are done."""
    queue = list(range(len(jobs)))
    running: dict[int, _Running] = {}

    def start(j: int) -> None:
        chain, task = jobs[j]
        t0 = time.perf_counter()
        backend.admit(task, [jobs[k][1] for k in running])
        search = depth_first(chain, task, budget, backend, chunk=chunk, slice_size=slice_size,
                             alternatives=alternatives)
        try:
            running[j] = _Running(search, next(search), time.perf_counter() - t0, 0.0)
        except StopIteration as stop:  # nothing under the cutoff to run
            done(j, result_of(chain, budget, stop.value, time.perf_counter() - t0, 0.0))

    while queue or running:
        while queue and len(running) < width:
            j = queue.pop(0)
            if running and jobs[j][1].n_examples != jobs[next(iter(running))][1].n_examples:
                queue.insert(0, j)  # another example count: after the running ones finish
                break
            start(j)
        if not running:
            continue
        t0, compiled_before = time.perf_counter(), backend.compile_seconds
        order = list(running)
        replies = backend.apply_many([running[j].request for j in order])
        wall, compiling = time.perf_counter() - t0, backend.compile_seconds - compiled_before
        rows = np.array([len(running[j].request.portions) for j in order], float)
        for j, reply, share in zip(order, replies, rows / rows.sum(), strict=True):
            entry = running[j]
            t1 = time.perf_counter()
            try:
                entry.request = entry.search.send(reply)
                entry.seconds += wall * share + time.perf_counter() - t1
                entry.compile_seconds += compiling * share
            except StopIteration as stop:
                del running[j]
                seconds = entry.seconds + wall * share + time.perf_counter() - t1
                done(j, result_of(jobs[j][0], budget, stop.value, seconds, entry.compile_seconds + compiling * share))
