"""A pool of Ray actors, each a warm engine kept for a whole run, through which a driver
maps chunks of work (docs/cluster.md).

The search (`search.cluster`) and the arm's suite (`robot.suite`) use it the same way:
every chunk is handed to an idle actor, its result comes back to the driver as soon as
it is done, and only the driver writes anything. A chunk whose actor dies (its process
killed, its host lost) goes back to the head of the queue and a new actor is started in
the dead one's slot, so each chunk's result reaches the driver exactly once.

Ray is an optional extra (`pip install 'vccjax[cluster]'`), imported only here and only
when a pool is made.
"""

from __future__ import annotations

import os
from collections import deque
from collections.abc import Callable, Sequence

MAX_TRIES = 3  # a chunk is run again after its actor dies, at most this many times


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


def pin(slot: int, threads: int) -> None:
    """Keep this process to `threads` cores of its host, chosen by its slot: XLA sizes its
    thread pool by the cores a process may use, so workers on one host do not fight over
    them (and, unlike XLA flags, pinning leaves the compile cache's keys as they are)."""
    cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    if cores and threads < len(cores):
        os.sched_setaffinity(0, {cores[(slot * threads + k) % len(cores)] for k in range(threads)})


class ActorPool:
    """`workers` actors of `actor_class` (default: one per `threads` CPUs of the cluster),
    made as `actor_class(*args_of(slot))`. Use as a context manager, or call `close()`:
    it stops the actors, and Ray itself when this pool started it."""

    def __init__(self, actor_class: type, args_of: Callable[[int], tuple], workers: int | None = None,
                 address: str | None = None, threads: int = 1):
        if (workers is not None and workers < 1) or threads < 1:
            raise ValueError("--workers and the threads per worker must be at least 1")
        ray = ray_module()
        self._started_ray = connect(workers, address)
        self._remote, self._args_of, self.threads = ray.remote(actor_class), args_of, threads
        n = workers or max(1, int(ray.cluster_resources().get("CPU", 1)) // threads)
        self.actors = [self._start(slot) for slot in range(n)]
        self.in_flight: dict[int, int] = {}  # actor slot -> the chunk it is running
        self.retried = 0  # chunks run again because their actor died

    def _start(self, slot: int):
        return self._remote.options(num_cpus=self.threads).remote(*self._args_of(slot))

    def pids(self) -> list[int]:
        """Each actor slot's process id (actor classes define `pid()`; a test kills one)."""
        ray = ray_module()
        return ray.get([a.pid.remote() for a in self.actors])

    def map(self, method: str, chunks: Sequence[tuple], done: Callable[[int, object], None]) -> None:
        """`actor.<method>(*chunks[i])` for every i, on whichever actor is idle;
        `done(i, result)` on this process, once per chunk, as each finishes."""
        ray = ray_module()
        lost = (ray.exceptions.RayActorError, ray.exceptions.WorkerCrashedError, ray.exceptions.ActorDiedError)
        queue, idle = deque(range(len(chunks))), deque(range(len(self.actors)))
        pending: dict = {}  # object ref -> (actor slot, chunk)
        tries: dict[int, int] = {}  # chunk -> times its actor died under it
        while queue or pending:
            while queue and idle:
                slot, i = idle.popleft(), queue.popleft()
                pending[getattr(self.actors[slot], method).remote(*chunks[i])] = (slot, i)
                self.in_flight[slot] = i
            (ref,), _ = ray.wait(list(pending), num_returns=1)
            slot, i = pending.pop(ref)
            self.in_flight.pop(slot, None)
            try:
                result = ray.get(ref)
            except lost:
                tries[i] = tries.get(i, 0) + 1
                if tries[i] > MAX_TRIES:  # a chunk that keeps killing its actor is no lost host
                    raise RuntimeError(f"chunk {i} of {len(chunks)} killed its worker {MAX_TRIES + 1} times; "
                                       "see the Ray logs (/tmp/ray/session_latest/logs)") from None
                queue.appendleft(i)  # run again, on whichever actor is free first
                self.retried += 1
                self.actors[slot] = self._start(slot)
                idle.append(slot)
                continue
            idle.append(slot)
            done(i, result)

    def close(self) -> None:
        ray = ray_module()
        for a in self.actors:
            ray.kill(a)
        self.actors = []
        if self._started_ray:
            ray.shutdown()

    def __enter__(self) -> ActorPool:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
