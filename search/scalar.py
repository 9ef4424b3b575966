"""The same search driven by the scalar reference interpreter: the baseline that the
batched search is measured against (`vcc bench search`), and its oracle in tests.

Only the machine differs: one `RefMachine` per (prefix, example), cloned per child and
stepped one instruction at a time. The enumeration, cutoff, budget and pruning are the
same code (`search.dfs`), so both visit the same programs and must find the same one.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from search.backend import Reply, Request
from search.explore import Searcher
from search.task import Task
from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import scenes_match

Machines = list[list[RefMachine]]  # per prefix, one machine per example


class ScalarBackend:
    """The `search.backend.Backend` on the reference interpreter. Nothing compiles and
    there is no device bank: each machine holds its scene."""

    compile_seconds = 0.0

    def __init__(self, cfg: VCCConfig = DEFAULT_CONFIG):
        self.cfg = cfg

    def root_states(self, task: Task) -> Machines:
        return [[RefMachine(scene, self.cfg, validate=False) for scene, _ in task.pairs]]

    def take(self, states: Machines, rows: np.ndarray) -> Machines:
        return [states[i] for i in rows]

    def join(self, parts: Sequence[Machines]) -> Machines:
        return [m for part in parts for m in part]

    def admit(self, task: Task, alongside: Sequence[Task]) -> None:
        pass

    def apply_many(self, requests: Sequence[Request]) -> list[Reply]:
        return [self.apply(r) for r in requests]

    def apply(self, request: Request) -> Reply:
        """One request: each child's parent machines cloned and stepped by its portion,
        stopping at the first example it fails on; those that may end judged on the host."""
        chain, task = request.chain, request.task
        n = len(request.portions)
        children, failed, solved = [], np.zeros(n, bool), np.zeros(n, bool)
        for i, portion in enumerate(request.portions):
            machines = []
            for machine in request.states[request.parents[i]]:
                child = machine.clone()
                for op, arg in zip(chain.ops[portion], chain.args[portion], strict=True):
                    child.step(op, arg)
                machines.append(child)
                if child.failed:  # the program fails on this example: no need to run the rest
                    failed[i] = True
                    break
            children.append(machines)
            if not failed[i] and request.may_end[i]:
                solved[i] = self.solves(machines, task)
        return Reply(children, failed, solved)

    def solves(self, machines: list[RefMachine], task: Task) -> bool:
        """Whether a complete program's machines (one per example) explain every example."""
        return all(scenes_match(m.output_scene(), output, self.cfg.tau)
                   for m, (_, output) in zip(machines, task.pairs, strict=True))


class ScalarExplorer(Searcher):
    """The search on the reference interpreter (`ScalarBackend`)."""

    def __init__(self, cfg: VCCConfig = DEFAULT_CONFIG, chunk: int = 256, slice_size: int = 256, width: int = 32):
        super().__init__(ScalarBackend(cfg), chunk, slice_size, width)
