"""The program model: a vocabulary of atoms and subroutines, and a Markov model over it.

A program is a token sequence closed by the end marker; the collection of programs is
scored as one sequence that starts with the marker (paper, Methods, eq. 1). Order 1
conditions each token on the previous one, order 0 does not. Transitions are MAP
estimates with additive smoothing (pseudocount epsilon), so nothing is ruled out.
Description lengths are in nats.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from vccjax.machine.instructions import N_OPS, NAMES
from vccjax.machine.program import Subroutine


@dataclasses.dataclass(frozen=True)
class Vocabulary:
    """Atoms 0..26 (the instruction set), then subroutines; `end` is the marker's index.

    A subroutine's body is a token sequence (it may call earlier subroutines)."""

    bodies: tuple[tuple[int, ...], ...] = ()

    @property
    def size(self) -> int:
        return N_OPS + len(self.bodies)

    @property
    def end(self) -> int:
        return self.size

    def name(self, t: int) -> str:
        return NAMES[t] if t < N_OPS else f"sub{t - N_OPS}"

    def atoms(self, t: int) -> tuple[int, ...]:
        """The atomic ops a token expands to."""
        if t < N_OPS:
            return (t,)
        return tuple(a for u in self.bodies[t - N_OPS] for a in self.atoms(u))

    def expand(self, tokens: Sequence[int]) -> tuple[int, ...]:
        return tuple(a for t in tokens for a in self.atoms(t))

    def add(self, body: Sequence[int]) -> Vocabulary:
        return Vocabulary(self.bodies + (tuple(body),))

    def subroutines(self) -> dict[str, Subroutine]:
        """As `vccjax.machine.program.Subroutine`s, for `parse(text, library)`."""
        return {self.name(N_OPS + i): Subroutine(self.name(N_OPS + i), tuple(self.name(u) for u in b))
                for i, b in enumerate(self.bodies)}

    def to_json(self) -> list[list[str]]:
        return [[self.name(u) for u in b] for b in self.bodies]

    @classmethod
    def from_json(cls, bodies: list[list[str]]) -> Vocabulary:
        v = cls()
        for i, b in enumerate(bodies):
            ids = []
            for name in b:
                if name in NAMES:
                    ids.append(NAMES.index(name))
                elif name.startswith("sub") and name[3:].isdigit() and int(name[3:]) < i:
                    ids.append(N_OPS + int(name[3:]))
                else:
                    raise ValueError(f"subroutine {i}: unknown token {name!r}")
            v = v.add(ids)
        return v


def transition_counts(seqs: Sequence[Sequence[int]], size: int) -> np.ndarray:
    """(size+1, size+1) counts; row/column `size` is the end marker (start = from end)."""
    end = size
    counts = np.zeros((size + 1, size + 1))
    for s in seqs:
        path = [end, *s, end]
        np.add.at(counts, (path[:-1], path[1:]), 1.0)
    return counts


@dataclasses.dataclass(frozen=True)
class MarkovModel:
    """log p(next | previous) over tokens and the end marker (order 0: rows all equal)."""

    logp: np.ndarray  # (V+1, V+1)
    order: int
    epsilon: float

    @property
    def end(self) -> int:
        return self.logp.shape[0] - 1

    @classmethod
    def uniform(cls, size: int, order: int = 1) -> MarkovModel:
        return cls(np.full((size + 1, size + 1), -np.log(size + 1)), order, 0.0)

    @classmethod
    def fit(cls, seqs: Sequence[Sequence[int]], size: int, order: int = 1, epsilon: float = 0.1) -> MarkovModel:
        return cls.from_counts(transition_counts(seqs, size), order, epsilon)

    @classmethod
    def from_counts(cls, counts: np.ndarray, order: int = 1, epsilon: float = 0.1) -> MarkovModel:
        """The MAP model of (size+1, size+1) transition counts (`transition_counts`)."""
        size = counts.shape[0] - 1
        if order == 0:
            counts = np.broadcast_to(counts.sum(0, keepdims=True), counts.shape)
        elif order != 1:
            raise ValueError(f"order must be 0 or 1, got {order}")
        p = (counts + epsilon) / (counts.sum(1, keepdims=True) + epsilon * (size + 1))
        return cls(np.log(p), order, epsilon)

    def description_length(self, seqs: Sequence[Sequence[int]]) -> float:
        """-log p of the collection, in nats."""
        counts = transition_counts(seqs, self.end)
        return float(-(counts * self.logp).sum())


def collection_dl(seqs: Sequence[Sequence[int]], size: int, order: int, epsilon: float) -> float:
    """Description length of sequences under the MAP model fitted on them (what compression minimises)."""
    return MarkovModel.fit(seqs, size, order, epsilon).description_length(seqs)
