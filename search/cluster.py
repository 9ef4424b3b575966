"""Explore-compress over a Ray cluster (docs/cluster.md).

The concepts of an iteration go out in chunks of `width` to worker actors; each worker
keeps one warm, compiled search engine (`search.explore.Explorer`) for the whole run, on
cores of its own (`threads` each), so workers on one host do not fight over its cores. A chunk's results come back as soon as it is done, and only the driver
hands them on (`done`), so `search.induce` stays the one writer of `results.jsonl`.

`ClusterSearcher` stands in for the single-process `Explorer`: it has the same
`search_many(jobs, budget, done)`. A job is a concept's `Chain` (the iteration's model
and the concept's argument beliefs) and its `Task`, so the model the driver refits
between iterations reaches the workers with the next iteration's chunks.

A worker that dies mid-chunk (its process killed, its host lost) costs only that chunk's
work: the chunk goes back to the queue, a new worker is started in the dead one's place,
and `done` is still called exactly once per concept. A driver that dies resumes from the
run folder, as a single-process run does.

Ray is an optional extra (`pip install 'vccjax[cluster]'`); it is imported only here,
and only when a cluster is asked for.
"""

from __future__ import annotations

import os
from collections import deque
from collections.abc import Callable, Sequence

from search.chain import Chain
from search.dfs import Alternatives
from search.result import Result
from search.task import Task

def ray_module():
    """Ray, or a one-line reason it is missing."""
    try:
        import ray
    except ImportError:
        raise RuntimeError("--cluster ray needs Ray: pip install 'vccjax[cluster]'") from None
    return ray


def connect(workers: int | None = None, address: str | None = None) -> bool:
    """Join the cluster at `address` (default: $RAY_ADDRESS) or, without one, start a
    local cluster of `workers` CPUs. Returns True when this call started Ray."""
    ray = ray_module()
    if ray.is_initialized():
        return False
    address = address or os.environ.get("RAY_ADDRESS") or None
    quiet = {"logging_level": "ERROR", "log_to_driver": False}
    if address:
        ray.init(address=address, **quiet)
    else:
        ray.init(num_cpus=workers or os.cpu_count() or 1, include_dashboard=False, **quiet)
    return True


class _Worker:
    """One search engine in its own process (a Ray actor, `ClusterSearcher._start`),
    kept to `threads` cores of its host: XLA sizes its thread pool by the cores a process
    may use, and pinning (not XLA flags, which are part of the compile cache's key)
    lets a worker reuse what any process of this install compiled before."""

    def __init__(self, width: int, threads: int, slot: int):
        cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
        if cores and threads < len(cores):
            os.sched_setaffinity(0, {cores[(slot * threads + k) % len(cores)] for k in range(threads)})
        from vccjax import runtime

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
    cluster), chunks of `width` concepts each. Use as a context manager, or call
    `close()`: it stops the workers, and Ray itself when this searcher started it."""

    def __init__(self, workers: int | None = None, address: str | None = None, width: int = 32, threads: int = 1):
        if workers is not None and workers < 1 or width < 1 or threads < 1:
            raise ValueError("--workers, --width and the threads per worker must be at least 1")
        ray = ray_module()
        self._started_ray = connect(workers, address)
        self.width, self.threads = width, threads
        self._remote = ray.remote(_Worker)
        n = workers or max(1, int(ray.cluster_resources().get("CPU", 1)) // threads)
        self.actors = [self._start(slot) for slot in range(n)]
        self.in_flight: dict[int, list[int]] = {}  # worker slot -> the concepts (job indices) it is running
        self.retried = 0  # chunks run again because their worker died

    def _start(self, slot: int):
        return self._remote.options(num_cpus=self.threads).remote(self.width, self.threads, slot)

    def worker_pids(self) -> list[int]:
        """Each worker slot's process id (a test kills one)."""
        ray = ray_module()
        return ray.get([a.pid.remote() for a in self.actors])

    def search_many(self, jobs: Sequence[tuple[Chain, Task]], budget: int,
                    done: Callable[[int, Result], None], alternatives: Alternatives | None = None) -> None:
        """Every job searched once; `done(index, result)` called on this process, once per
        job, as chunks finish (in no fixed order, as `Explorer.search_many`)."""
        ray = ray_module()
        lost = (ray.exceptions.RayActorError, ray.exceptions.WorkerCrashedError, ray.exceptions.ActorDiedError)
        queue = deque(list(range(i, min(i + self.width, len(jobs)))) for i in range(0, len(jobs), self.width))
        idle = deque(range(len(self.actors)))
        pending: dict = {}  # object ref -> (worker slot, chunk)
        while queue or pending:
            while queue and idle:
                slot, chunk = idle.popleft(), queue.popleft()
                ref = self.actors[slot].search.remote([jobs[j] for j in chunk], budget, alternatives)
                pending[ref] = (slot, chunk)
                self.in_flight[slot] = chunk
            (ref,), _ = ray.wait(list(pending), num_returns=1)
            slot, chunk = pending.pop(ref)
            self.in_flight.pop(slot, None)
            try:
                results = ray.get(ref)
            except lost:
                queue.appendleft(chunk)  # run again, on whichever worker is free first
                self.retried += 1
                self.actors[slot] = self._start(slot)
                idle.append(slot)
                continue
            idle.append(slot)
            for j, r in zip(chunk, results, strict=True):
                done(j, r)

    def close(self) -> None:
        ray = ray_module()
        for a in self.actors:
            ray.kill(a)
        self.actors = []
        if self._started_ray:
            ray.shutdown()

    def __enter__(self) -> ClusterSearcher:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
