"""The same search driven by the scalar reference interpreter: the baseline that the
batched search is measured against (`vcc bench search`), and its oracle in tests.

Only the machine differs: one `RefMachine` per (prefix, example), cloned per child and
stepped one instruction at a time. The enumeration, cutoff, budget and pruning are
`Explorer`'s, so both visit the same programs and must find the same one.
"""

from __future__ import annotations

import numpy as np

from search.explore import Explorer, Request, Task
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import scenes_match


class ScalarExplorer(Explorer):
    def root_states(self, task: Task):
        return [[RefMachine(a, self.cfg, validate=False) for a, _ in task.pairs]]

    def take(self, states, idx: np.ndarray):
        return [states[i] for i in idx]

    def prepare(self, tasks) -> None:
        pass  # no device bank: each machine holds its scene

    def admit(self, task, active) -> None:
        pass

    def apply_many(self, requests: list[Request]):
        return [self.apply(r) for r in requests]

    def apply(self, request: Request):
        chain, task, portions, may_end = request.chain, request.task, request.portions, request.may_end
        states = [request.states[i] for i in request.parents]
        out, failed, ok = [], np.zeros(len(portions), bool), np.zeros(len(portions), bool)
        for i, (machines, z) in enumerate(zip(states, portions)):
            kids = []
            for m in machines:
                k = m.clone()
                for op, arg in zip(chain.ops[z], chain.args[z]):
                    k.step(op, arg)
                kids.append(k)
                if k.failed:  # the program fails on this example: no need to run the rest
                    failed[i] = True
                    break
            out.append(kids)
            if not failed[i] and may_end[i]:
                ok[i] = all(scenes_match(k.output_scene(), b, self.cfg.tau)
                            for k, (_, b) in zip(kids, task.pairs))
        return out, failed, ok
