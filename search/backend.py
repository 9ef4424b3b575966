"""What the depth-first search needs from a machine: the interface between the
enumeration (`search.dfs`) and what runs programs (`search.jax_backend` on the JAX
emulator, `search.scalar` on the reference interpreter).

The search never looks inside a state: it asks for the empty program's states, sends a
`Request` (children to step by one portion each and, for those that may end, to judge)
and keeps rows of the states it gets back. So the two backends may hold states however
suits them (packed arrays, lists of machines) and both visit the same tree.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple, Protocol

import numpy as np

from search.chain import Chain
from search.task import Task


class Request(NamedTuple):
    """What a concept's search asks the machine to run: each child is its parent's state
    (`states[parents[i]]`) stepped by one portion; `may_end` marks complete programs to judge."""

    chain: Chain
    task: Task
    states: object  # the frame's states, as the backend holds them (one entry per prefix)
    parents: np.ndarray  # (n,) row of each child's parent in `states`
    portions: np.ndarray  # (n,) the portion (index into the chain) each child adds
    may_end: np.ndarray  # (n,) bool: a complete program under the cutoff, to be judged


class Reply(NamedTuple):
    """The machine's answer to a `Request`, one entry per child."""

    states: object  # the children's states (valid until the next request: keep rows with `take`)
    failed: np.ndarray  # (n,) bool: failed on some example (pruned with its subtree)
    solved: np.ndarray  # (n,) bool: explains every example (read only where `may_end` and not `failed`)


class Backend(Protocol):
    """A machine the depth-first search runs programs on."""

    @property
    def compile_seconds(self) -> float:
        """Seconds spent compiling so far (0 where nothing compiles)."""
        ...

    def root_states(self, task: Task) -> object:
        """The states of the empty program on every example of `task` (one prefix)."""
        ...

    def take(self, states: object, rows: np.ndarray) -> object:
        """Rows `rows` of a reply's states, copied so that they outlive the next request."""
        ...

    def join(self, parts: Sequence[object]) -> object:
        """States of several frames as one (rows in order), for a request that runs
        children of several frames together."""
        ...

    def admit(self, task: Task, alongside: Sequence[Task]) -> None:
        """Get ready to run `task`'s programs while `alongside` (tasks already admitted and
        still searched) keep running theirs."""
        ...

    def apply_many(self, requests: Sequence[Request]) -> list[Reply]:
        """Answer several requests (of admitted tasks) at once, in order."""
        ...
