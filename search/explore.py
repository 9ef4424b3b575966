"""Exploration: enumerate every program under a description-length cutoff, on a machine.

The parts, one idea each:
- `search.dfs`: the depth-first enumeration, budget cutoff and pruning (a coroutine
  that asks for slices of children to be run);
- `search.backend`: what it asks of a machine (`Backend`, `Request`, `Reply`);
- `search.jax_backend`: the batched JAX emulator (bank of scenes, device calls, loop
  replay, judging on device), with `search.device_calls` for padding, sharding and
  compile-time accounting;
- `search.scalar`: the reference interpreter, the baseline and the tests' oracle;
- `search.lockstep`: many concepts' searches interleaved so they share device calls.

This module puts them together: `Searcher` runs the search on a backend, one concept
(`search`) or many in lockstep (`search_many`); `Explorer` is the searcher on the JAX
emulator, `search.scalar.ScalarExplorer` the one on the reference interpreter.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import jax

from search.backend import Backend, Reply, Request
from search.chain import Chain
from search.device_calls import BUCKETS
from search.dfs import MAX_PORTIONS, Alternatives, depth_first
from search.jax_backend import JaxBackend
from search.lockstep import search_in_lockstep
from search.result import Result, result_of
from search.task import Task
from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig

__all__ = ["MAX_PORTIONS", "Alternatives", "Backend", "Explorer", "Reply", "Request", "Result", "Searcher", "Task"]


class Searcher:
    """The depth-first search on `backend`: `chunk` live prefixes per frame, children run
    in slices of `slice_size` (a lockstep round: up to `width` concepts' slices)."""

    def __init__(self, backend: Backend, chunk: int = 256, slice_size: int = 256, width: int = 32):
        self.backend = backend
        self.chunk = chunk
        self.slice_size = slice_size
        self.width = width

    def search(self, chain: Chain, task: Task, budget: int,
               progress: Callable[[int], None] | None = None, alternatives: Alternatives | None = None,
               prefix: Sequence[int] = ()) -> Result:
        """The shortest program under the budget's cutoff that explains every example;
        `progress(n)` is told of each slice of n children run; with `alternatives`, other
        programs that explain them too (`search.dfs.Alternatives`); with `prefix`
        (portions), the programs that start with it (`search.dfs.depth_first`)."""
        t0, compiled_before = time.perf_counter(), self.backend.compile_seconds
        self.backend.admit(task, [])
        search = depth_first(chain, task, budget, self.backend, chunk=self.chunk, slice_size=self.slice_size,
                             progress=progress, alternatives=alternatives, prefix=prefix)
        try:
            request = next(search)
            while True:
                request = search.send(self.backend.apply_many([request])[0])
        except StopIteration as stop:
            outcome = stop.value
        return result_of(chain, budget, outcome, time.perf_counter() - t0,
                         self.backend.compile_seconds - compiled_before)

    def search_many(self, jobs: Sequence[tuple[Chain, Task]], budget: int,
                    done: Callable[[int, Result], None], alternatives: Alternatives | None = None) -> None:
        """Explore every (chain, task) job, `width` at a time in lockstep; `done(index,
        result)` is called as each finishes (`search.lockstep.search_in_lockstep`)."""
        search_in_lockstep(self.backend, jobs, budget, done, width=self.width, chunk=self.chunk,
                           slice_size=self.slice_size, alternatives=alternatives)


class Explorer(Searcher):
    """The search on the JAX emulator (`search.jax_backend.JaxBackend`); one instance keeps
    its compiled steps. Batches are padded to one of `buckets` sizes, their pieces dealt
    out to `devices` (default: all JAX devices; `search.device_calls`); `width` concepts
    share a lockstep round."""

    backend: JaxBackend

    def __init__(self, cfg: VCCConfig = DEFAULT_CONFIG, chunk: int = 256, slice_size: int = 256,
                 buckets: Sequence[int] = BUCKETS, width: int = 32,
                 devices: Sequence[jax.Device] | None = None):
        super().__init__(JaxBackend(cfg, buckets, width, devices), chunk, slice_size, width)

    @property
    def cfg(self) -> VCCConfig:
        return self.backend.cfg

    @property
    def devices(self) -> list[jax.Device]:
        return self.backend.calls.devices

    @property
    def compile_seconds(self) -> float:
        """Seconds spent compiling, all searches so far."""
        return self.backend.compile_seconds
