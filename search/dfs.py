"""The enumeration: every program under a description-length cutoff, depth first.

Depth-first over chunks of the frontier (memory stays bounded by depth x chunk): a
frame holds up to `chunk` live prefixes with their states on all examples; its
children (prefix + one portion) are made cheapest first and handed to the backend in
slices, a slice filled from the frames below the top when the top has few left
(`_fill`). A child that fails on any example is dropped with its whole subtree
(docs/vcc.md section 3); so is one whose cheapest completion costs more than the cutoff. A child
that may end is a complete program: the backend judges it against every example's
output. The search runs to the end of the tree (paper: DFS to completion) but, once a
program is found, only cheaper ones can replace it, so the cutoff drops to just below
its cost.

Budget: the M most probable programs, exactly. The cutoff b* is the first cost (in
bins) at which at least M programs exist; all programs cheaper than b* are checked,
and programs costing exactly b* until M have been checked.

The search is a coroutine (`depth_first`): it yields a `Request` and receives the
backend's `Reply`, so one caller can interleave many concepts' searches and answer
their requests together (`search.lockstep`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Generator, Hashable, Sequence
from typing import NamedTuple

import numpy as np

from search.backend import Backend, Reply, Request
from search.chain import NOT_STARTED, OUTSIDE, Chain, cutoff_for_budget
from search.result import Outcome
from search.task import Task

MAX_PORTIONS = 40  # deepest path searched (portions)


class _Children(NamedTuple):
    """A frame's children under the cutoff when the frame was first visited, cheapest first."""

    parent: np.ndarray  # row of the parent prefix in the frame
    portion: np.ndarray  # the portion the child adds
    cost: np.ndarray  # bins so far (the end not counted)
    bound: np.ndarray  # bins of the cheapest complete program through the child


@dataclasses.dataclass
class _Frame:
    """Up to `chunk` live prefixes of one depth, and how far their children have been run."""

    states: object  # as the backend holds them, one entry per prefix
    last_token: np.ndarray  # (n,) last token (the end marker at the root)
    syntax: np.ndarray  # (n,) syntax automaton state
    cost: np.ndarray  # (n,) bins so far (the end not counted)
    path: np.ndarray  # (n, MAX_PORTIONS) portions so far, -1 padded
    depth: int
    children: _Children | None = None  # made when the frame is first visited
    next_child: int = 0  # children before this one have been run


class Alternatives(NamedTuple):
    """Also keep other programs that explain every example (the rivals `vcc learn` asks
    about): at most `keep`, the cheapest, costing at most `margin_bins` more than the
    best, found within `extra_programs` programs judged after the first fit. The best
    program is the one the plain search finds: the extra search only keeps the cutoff
    higher for a while, and a program replaces the best only when strictly cheaper.

    `behaviour`, when given, maps a fit's portions to a key of what it does (its outputs
    on a few probe scenes): fits with one key count as one, the cheapest kept, and those
    that behave like the best are not kept at all. Without it, cheap variants that do the
    same thing (a useless `fixate` in front) fill the `keep` places and cut the search
    short of a rival that does something else."""

    margin_bins: int
    keep: int
    extra_programs: int
    behaviour: Callable[[np.ndarray], Hashable] | None = None


class _Budget:
    """The cutoff and the programs counted against the budget, as the search lowers it."""

    def __init__(self, chain: Chain, budget: int, alternatives: Alternatives | None = None,
                 root: tuple[int, int] | None = None):
        self.b_star, self.counts = cutoff_for_budget(chain, budget, root)
        cheaper = int(self.counts[self.b_star - 1]) if self.b_star > 0 else 0
        self.quota = budget - cheaper  # programs of cost exactly b* still allowed
        self.cutoff = self.b_star  # the most a program may cost (bins)
        self.programs = 0  # complete programs counted
        self.best: tuple[int, np.ndarray, Hashable] | None = None  # (cost, path, behaviour or None)
        self.alternatives = alternatives
        self.fits: list[tuple[int, np.ndarray, Hashable]] = []  # every fit, kept only with alternatives
        self.extra_left = alternatives.extra_programs if alternatives else 0

    def counts_program(self, cost: int) -> bool:
        """Count a complete program that ran on every example; False if it lies beyond the
        budget (a program at b* once M programs have been counted)."""
        if cost == self.b_star:
            if self.quota <= 0:
                return False
            self.quota -= 1
            if self.quota == 0:
                self.cutoff = min(self.cutoff, self.b_star - 1)
        self.programs += 1
        if self.best is not None and self.extra_left > 0:
            self.extra_left -= 1
            if self.extra_left == 0:  # the extra search is spent: only cheaper programs from now on
                self.cutoff = min(self.cutoff, self.best[0] - 1)
        return True

    def found(self, cost: int, path: np.ndarray) -> None:
        """A program that explains every example: keep it if it is the cheapest so far."""
        alt = self.alternatives
        wanted = alt is not None and alt.behaviour is not None and (
            self.best is None or cost <= self.best[0] + alt.margin_bins)  # the key runs programs: only when kept
        fit = (cost, path.copy(), alt.behaviour(path) if wanted else None)
        if self.best is None or cost < self.best[0]:
            self.best = fit
        if alt is not None:  # the `keep` cheapest within the margin (stable: ties in finding order)
            within = sorted((f for f in [*self.fits, fit] if f[0] <= self.best[0] + alt.margin_bins),
                            key=lambda f: f[0])
            if alt.behaviour is not None:
                within = _one_per_behaviour(self.best, within)
            self.fits = within[: alt.keep]
        self.cutoff = min(self.cutoff, self._limit())

    def _limit(self) -> int:
        """The cutoff a found program allows: below the best, or with alternatives wanted,
        up to the margin above it until `keep` of them are in hand."""
        best = self.best[0]
        alt = self.alternatives
        if alt is None or self.extra_left <= 0:
            return best - 1
        if len(self.fits) >= alt.keep:
            return min(best + alt.margin_bins, self.fits[-1][0] - 1)
        return best + alt.margin_bins

    def kept(self) -> tuple[tuple[int, np.ndarray], ...]:
        """The alternatives kept, cheapest first (ties in finding order), the best excluded."""
        if self.best is None or self.alternatives is None:
            return ()
        return tuple(f[:2] for f in self.fits if f is not self.best)[: max(self.alternatives.keep - 1, 0)]


def _one_per_behaviour(best: tuple, fits: list[tuple]) -> list[tuple]:
    """The best, and the cheapest of `fits` (cheapest first) for each other behaviour."""
    seen, kept = {best[2]}, [best]
    for f in fits:
        if f[2] not in seen:
            seen.add(f[2])
            kept.append(f)
    return sorted(kept, key=lambda f: f[0])


def depth_first(chain: Chain, task: Task, budget: int, backend: Backend, *, chunk: int, slice_size: int,
                progress: Callable[[int], None] | None = None,
                alternatives: Alternatives | None = None,
                prefix: Sequence[int] = ()) -> Generator[Request, Reply, Outcome]:
    """The search of one concept as a coroutine: yields a `Request` for each slice of up
    to `slice_size` children, receives the backend's `Reply`; returns the `Outcome`.
    `backend` is used for root states and `take` only (the caller applies the requests).

    `prefix` (portions) makes it a search for continuations: the prefix is run (and
    judged, where it may end), then every program that starts with it is enumerated by
    the cost of what follows (conditioned on the prefix's last token), the budget
    counting continuations, the empty one included. The programs found hold the prefix;
    their costs and ranks are the continuation's."""
    last, syntax = chain.end, NOT_STARTED
    for z in prefix:
        last, syntax = int(chain.tok[z]), int(chain.next_syn[chain.tok[z], syntax])
        if syntax < 0:
            raise ValueError("the prefix breaks the program syntax")
    limits = _Budget(chain, budget, alternatives, (last, syntax) if len(prefix) else None)
    path = np.full((1, MAX_PORTIONS), -1, np.int32)
    path[0, : len(prefix)] = prefix
    states = backend.root_states(task)
    for k, z in enumerate(prefix):  # one child per step: the prefix's states on every example
        ends = k == len(prefix) - 1 and syntax == OUTSIDE  # the prefix itself is a program to judge
        reply = yield Request(chain, task, states, np.array([0]), np.array([z]), np.array([ends]))
        if reply.failed[0]:  # no program through the prefix runs
            return Outcome(None, k + 1, 0, limits.b_star, limits.counts, ())
        if ends and limits.counts_program(int(chain.trans_bins[last, chain.end])) and reply.solved[0]:
            limits.found(int(chain.trans_bins[last, chain.end]), path[0])
        states = backend.take(reply.states, np.array([0]))
    frames = [_Frame(states, np.array([last]), np.array([syntax]), np.array([0]), path, len(prefix))]
    nodes = len(prefix)  # the prefix's steps
    end_bins = chain.trans_bins[:, chain.end]  # the cost of ending after each token
    while frames:
        slices = _fill(chain, frames, limits.cutoff, slice_size)
        if not slices:
            break
        parts = [_Part(chain, frame, picked, limits.cutoff, end_bins) for frame, picked in slices]
        if len(parts) == 1:
            states, parents = parts[0].frame.states, parts[0].parents
        else:  # the parents the slices use, of every frame, as one array
            used = [np.unique(p.parents, return_inverse=True) for p in parts]
            states = backend.join([backend.take(p.frame.states, u) for p, (u, _) in zip(parts, used)])
            offsets = np.cumsum([0] + [len(u) for u, _ in used[:-1]])
            parents = np.concatenate([inv.reshape(-1) + o for (_, inv), o in zip(used, offsets)])
        reply = yield Request(chain, task, states, parents, np.concatenate([p.portions for p in parts]),
                              np.concatenate([p.may_end for p in parts]))
        start = 0
        for p in parts:  # each slice's children, as its frame's alone
            rows = np.arange(start, start + len(p.portions))
            start += len(p.portions)
            nodes += len(rows)
            # a program counts only under the cutoff as it is now (a find earlier in this
            # request may have lowered it), so counting does not depend on how slices are made
            for i in np.nonzero(~reply.failed[rows] & p.may_end)[0]:
                if (p.cost_ended[i] <= limits.cutoff and limits.counts_program(int(p.cost_ended[i]))
                        and reply.solved[rows[i]]):
                    limits.found(int(p.cost_ended[i]), p.paths[i])
            if progress:
                progress(len(rows))
            live = (~reply.failed[rows] & (p.cost + chain.min_rest[p.tokens, np.maximum(p.syntax, 0)] <= limits.cutoff)
                    & (p.syntax >= 0))
            if p.frame.depth + 1 < MAX_PORTIONS:
                keep = np.nonzero(live)[0]
                for part in np.array_split(keep, max(1, -(-len(keep) // chunk))):  # chunks of at most `chunk`
                    if len(part):
                        frames.append(_Frame(backend.take(reply.states, rows[part]), p.tokens[part],
                                             p.syntax[part], p.cost[part], p.paths[part], p.frame.depth + 1))
    best = limits.best[:2] if limits.best else None
    return Outcome(best, nodes, limits.programs, limits.b_star, limits.counts, limits.kept())


def _children(chain: Chain, frame: _Frame, cutoff: int) -> _Children:
    """Every syntactic child of the frame's prefixes that may complete under the cutoff,
    the most probable first (ties in parent, then portion order)."""
    tokens = chain.tok[None, :]
    cost = frame.cost[:, None] + chain.trans_bins[frame.last_token[:, None], tokens] + chain.argbins[None, :]
    syntax = chain.next_syn[tokens, frame.syntax[:, None]]
    bound = cost + chain.min_rest[tokens, np.maximum(syntax, 0)]
    parent, portion = np.nonzero((syntax >= 0) & (bound <= cutoff))
    order = np.argsort(cost[parent, portion], kind="stable")
    parent, portion = parent[order], portion[order]
    return _Children(parent, portion, cost[parent, portion], bound[parent, portion])


class _Part:
    """One frame's slice of children in a request: what they add, cost and complete."""

    def __init__(self, chain: Chain, frame: _Frame, picked: np.ndarray, cutoff: int, end_bins: np.ndarray):
        self.frame = frame
        self.parents, self.portions, self.cost = (a[picked] for a in frame.children[:3])
        self.tokens = chain.tok[self.portions]
        self.syntax = chain.next_syn[self.tokens, frame.syntax[self.parents]]
        self.cost_ended = self.cost + end_bins[self.tokens]
        self.may_end = (self.syntax == OUTSIDE) & (self.cost_ended <= cutoff)
        self.paths = frame.path[self.parents].copy()
        if frame.depth < MAX_PORTIONS:
            self.paths[:, frame.depth] = self.portions


def _fill(chain: Chain, frames: list[_Frame], cutoff: int, size: int) -> list[tuple[_Frame, np.ndarray]]:
    """Slices of up to `size` children in all: the top frame's next ones, then, while
    there is room, the next frames' down the stack (a deep frame often has only a few
    children under the cutoff, and a round of a few rows costs nearly as much as a full
    one). Frames with nothing left are dropped. Every frame is run to its end whatever
    the order, so the search covers the same programs; only which of equally cheap
    programs is met first (ties at b* included), and how many children a round runs
    past a find, can differ from a one-frame-at-a-time order."""
    out, room, k = [], size, len(frames) - 1
    while k >= 0 and room > 0:
        frame = frames[k]
        if frame.children is None:
            frame.children = _children(chain, frame, cutoff)
        picked = _next_slice(frame, cutoff, room)
        if picked is None:
            del frames[k]
        else:
            out.append((frame, picked))
            room -= len(picked)
        k -= 1
    return out


def _next_slice(frame: _Frame, cutoff: int, size: int) -> np.ndarray | None:
    """The next up to `size` children not yet run that are still under the cutoff (it
    may have dropped since the children were made), or None when none is left."""
    pending = np.nonzero(frame.children.bound[frame.next_child :] <= cutoff)[0] + frame.next_child
    if len(pending) == 0:
        return None
    picked = pending[:size]
    frame.next_child = int(picked[-1]) + 1
    return picked
