"""Explore-compress over a Ray cluster (docs/cluster.md).

The concepts of an iteration go out in chunks of `width` to worker actors
(`vccjax.actor_pool`); each worker keeps one warm, compiled search engine
(`search.explore.Explorer`) for the whole run, on cores of its own. A chunk's results
come back as soon as it is done, and only the driver hands them on (`done`), so
`search.induce` stays the one writer of `results.jsonl`.

`ClusterSearcher` stands in for the single-process `Explorer`: it has the same
`search_many(jobs, budget, done)`. A job is a concept's `Chain` (the iteration's model
and the concept's argument beliefs) and its `Task`, so the model the driver refits
between iterations reaches the workers with the next iteration's chunks. A worker that
dies mid-chunk costs only that chunk's work (the pool runs it again); a driver that dies
resumes from the run folder, as a single-process run does.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence

from search.chain import Chain
from search.dfs import Alternatives
from search.result import Result
from search.task import Task
from vccjax.actor_pool import ActorPool

__all__ = ["ClusterSearcher"]


class _Worker:
    """One search engine in its own process (a Ray actor), kept to `threads` cores."""

    def __init__(self, width: int, threads: int, slot: int):
        from vccjax import runtime
        from vccjax.actor_pool import pin

        pin(slot, threads)
        runtime.prepare()
        from search.explore import Explorer

        self.explorer = Explorer(width=width)

    def pid(self) -> int:
        return os.getpid()

    def search(self, jobs: list[tuple[Chain, Task]], budget: int,
               alternatives: Alternatives | None = None) -> list[Result]:
        out: list[Result | None] = [None] * len(jobs)
        self.explorer.search_many(jobs, budget, lambda j, r: out.__setitem__(j, r), alternatives)
        return out


class ClusterSearcher:
    """`search_many` over `workers` Ray actors (default: one per `threads` CPUs of the
    cluster), chunks of `width` concepts each. Use as a context manager, or `close()`."""

    def __init__(self, workers: int | None = None, address: str | None = None, width: int = 32, threads: int = 1):
        if width < 1:
            raise ValueError("--width must be at least 1")
        self.width = width
        self.pool = ActorPool(_Worker, lambda slot: (width, threads, slot), workers, address, threads)

    @property
    def actors(self) -> list:
        return self.pool.actors

    @property
    def in_flight(self) -> dict[int, int]:
        """Worker slot -> the chunk it is running."""
        return self.pool.in_flight

    @property
    def retried(self) -> int:
        return self.pool.retried

    def worker_pids(self) -> list[int]:
        return self.pool.pids()

    def search_many(self, jobs: Sequence[tuple[Chain, Task]], budget: int,
                    done: Callable[[int, Result], None], alternatives: Alternatives | None = None) -> None:
        """Every job searched once; `done(index, result)` called on this process, once per
        job, as chunks finish (in no fixed order, as `Explorer.search_many`)."""
        starts = list(range(0, len(jobs), self.width))
        chunks = [(list(jobs[s : s + self.width]), budget, alternatives) for s in starts]

        def chunk_done(i: int, results: list[Result]) -> None:
            for k, r in enumerate(results):
                done(starts[i] + k, r)

        self.pool.map("search", chunks, chunk_done)

    def close(self) -> None:
        self.pool.close()

    def __enter__(self) -> ClusterSearcher:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
