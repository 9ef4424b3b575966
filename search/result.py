"""What a search reports: the program found (as atoms and as searched, with subroutine
calls), its description length and rank, and what finding it cost."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from search.chain import Chain
from vccjax.machine.instructions import NAMES, arg_domain
from vccjax.machine.program import Program


class Alternative(NamedTuple):
    """Another program that explains every example (`search.dfs.Alternatives`)."""

    program: Program
    text: str  # as searched, with subroutine calls
    dl_nats: float


@dataclasses.dataclass
class Result:
    found: bool
    program: Program | None
    text: str | None  # compressed form (subroutine calls), as searched
    dl_nats: float | None
    dl_bins: int | None
    rank: int | None  # programs strictly more probable, + 1
    nodes: int  # portions run (prefixes visited)
    programs: int  # complete programs checked on all examples
    seconds: float  # wall time, compile included
    cutoff_bins: int
    budget: int
    compile_seconds: float = 0.0  # of `seconds`, spent compiling new (op, batch size) steps
    alternatives: tuple[Alternative, ...] = ()  # other programs that explain every example, when asked for


class Outcome(NamedTuple):
    """What a finished depth-first search returns (`search.dfs.depth_first`)."""

    best: tuple[int, np.ndarray] | None  # (cost in bins, portions -1 padded) of the cheapest program found
    nodes: int  # children stepped
    programs: int  # complete programs judged
    cutoff_bins: int  # b*, the budget's cutoff
    counts: np.ndarray  # counts[b]: programs of cost <= b (chain.cutoff_for_budget's table)
    alternatives: tuple = ()  # (cost, portions) of other fits kept, cheapest first


def result_of(chain: Chain, budget: int, outcome: Outcome, seconds: float, compile_seconds: float) -> Result:
    """The `Result` of a finished search, its program decoded and ranked."""
    if outcome.best is None:
        return Result(False, None, None, None, None, None, outcome.nodes, outcome.programs, seconds,
                      outcome.cutoff_bins, budget, compile_seconds)
    cost, path = outcome.best
    portions = [int(x) for x in path if x >= 0]
    rank = int(outcome.counts[cost - 1]) + 1 if cost > 0 else 1
    others = []
    for _, other in outcome.alternatives:
        steps = [int(x) for x in other if x >= 0]
        others.append(Alternative(program_of(chain, steps), text_of(chain, steps), chain.program_nats(steps)))
    return Result(True, program_of(chain, portions), text_of(chain, portions), chain.program_nats(portions), cost,
                  rank, outcome.nodes, outcome.programs, seconds, outcome.cutoff_bins, budget, compile_seconds,
                  tuple(others))


def rank_of(chain: Chain, bins: int) -> int:
    """The rank of a program of `bins` cost bins under `chain`: the programs strictly
    more probable, all of them counted however far past any budget, + 1."""
    return int(chain.count_table(budget=2**62, max_bins=bins)[bins - 1]) + 1 if bins > 0 else 1


def program_of(chain: Chain, portions: Sequence[int]) -> Program:
    """The atoms of a path of portions (subroutine calls expanded)."""
    ops = tuple(op for portion in portions for op in chain.ops[portion])
    args = tuple(arg for portion in portions for arg in chain.args[portion])
    return Program(ops, args)


def text_of(chain: Chain, portions: Sequence[int]) -> str:
    """A path of portions as searched: one token per portion (a subroutine by its name),
    with its arguments."""
    parts = []
    for portion in portions:
        token = int(chain.tok[portion])
        values = [arg_domain(NAMES[op])[arg] for op, arg in zip(chain.ops[portion], chain.args[portion], strict=True)
                  if arg_domain(NAMES[op])]
        name = chain.vocab.name(token)
        parts.append(f"{name}({', '.join(values)})" if values else name)
    return "; ".join(parts)
