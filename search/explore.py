"""Exploration: enumerate every program under a description-length cutoff, batched.

Depth-first over chunks of the frontier (memory stays bounded by depth x chunk): a
frame holds up to `chunk` live prefixes with their emulator states on all examples;
its children (prefix + one portion) are made in slices, grouped by instruction, and
stepped with `step_examples`, so every group runs one instruction's code over
(programs x examples) at once. A child that fails on any example is dropped with its
whole subtree (spec section 3). A child that may end is a complete program: it is
checked against every example's output on device (YES / NO, and ASK settled on the
host). The search runs to the end of the tree (paper: DFS to completion) but, once a
program is found, only cheaper ones can replace it, so the cutoff drops to just below
its cost.

Budget: the M most probable programs, exactly. The cutoff b* is the first cost (in
bins) at which at least M programs exist; all programs cheaper than b* are checked,
and programs costing exactly b* until M have been checked.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from collections.abc import Callable, Generator, Sequence

import jax
import jax.numpy as jnp
import numpy as np

from search.chain import NOT_STARTED, OUTSIDE, Chain, cutoff_for_budget
from vccjax.config import DEFAULT_CONFIG, VCCConfig
from vccjax.emulator import EMPTY_HANDED, loop_needs_iteration, replay_examples, step_examples
from vccjax.explain import ASK, YES, Target, load_target, verdict
from vccjax.instructions import NAMES, OP, arg_domain
from vccjax.program import Program
from vccjax.scene import Scene, scenes_match
from vccjax.state import (SceneConst, init_state, load_scene, output_scene, pack_state, packed_field, stack,
                          unpack_state)

MAX_PORTIONS = 40


@dataclasses.dataclass
class Task:
    """A concept's training examples, loaded once for the device."""

    pairs: list[tuple[Scene, Scene]]
    consts: SceneConst  # (E, ...)
    targets: Target  # (E, ...)

    @classmethod
    def from_pairs(cls, pairs: Sequence[tuple[Scene, Scene]], cfg: VCCConfig = DEFAULT_CONFIG) -> Task:
        if not pairs:
            raise ValueError("a task needs at least one example pair")
        return cls(list(pairs), stack([load_scene(a, cfg) for a, _ in pairs]),
                   stack([load_target(b, cfg) for _, b in pairs]))

    @property
    def n_examples(self) -> int:
        return len(self.pairs)


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


@functools.partial(jax.jit, static_argnums=0)
def judge(cfg: VCCConfig, consts: SceneConst, targets: Target, tasks, packed):
    """Verdicts (B, E) of packed states, row b against task `tasks[b]`'s outputs."""
    def row(task, s):
        c, t = jax.tree.map(lambda a: a[task], (consts, targets))
        return jax.vmap(functools.partial(verdict, cfg))(c, s, t)

    return jax.vmap(row)(tasks, unpack_state(packed, cfg))


@functools.partial(jax.jit, static_argnums=(0, 1, 6))
def advance(cfg: VCCConfig, op: int, consts: SceneConst, tasks, packed, args, replay: bool = True):
    """Step (B, E) packed states, each row a program of task `tasks[row]`, by `op`; return
    them and whether each program failed on any example."""
    new = step_examples(cfg, op, consts, tasks, unpack_state(packed, cfg), args, replay)
    return pack_state(new, cfg), jnp.any(new.failed, axis=1)


@functools.partial(jax.jit, static_argnums=(0, 1))
def replay(cfg: VCCConfig, op: int, consts: SceneConst, tasks, packed, args, pcs, active):
    """`replay_examples` on packed states."""
    return pack_state(replay_examples(cfg, op, consts, tasks, unpack_state(packed, cfg), args, pcs, active), cfg)


def _take(tree, idx: np.ndarray):
    return jax.tree.map(lambda a: a[idx], tree)


def _concat(trees):
    return jax.tree.map(lambda *xs: np.concatenate(xs), *trees)


@dataclasses.dataclass
class _Frame:
    states: object  # pytree of numpy (n, E, ...)
    last: np.ndarray  # (n,) last token (end marker at the root)
    syn: np.ndarray  # (n,)
    cost: np.ndarray  # (n,) bins so far (no end)
    hist: np.ndarray  # (n, MAX_PORTIONS) portion indices, -1 padded
    depth: int
    kids: tuple[np.ndarray, ...] | None = None  # parent, portion, cost, cheapest completion
    pos: int = 0


class Explorer:
    """Batched, pruned enumeration over a chain; one instance keeps its compiled steps.

    `search` explores one concept; `search_many` explores many in lockstep: each
    concept's depth-first search runs as a coroutine that asks for its next slice of
    children to be stepped, and one round steps every active concept's slice together,
    grouped by instruction, so a group holds the programs of many concepts. The
    concepts' scenes sit in a bank of `width` slots on the device (a fixed shape: each
    instruction compiles once whatever the number of concepts)."""

    def __init__(self, cfg: VCCConfig = DEFAULT_CONFIG, chunk: int = 256, slice_size: int = 256,
                 buckets: Sequence[int] = (16, 64, 256, 1024, 4096), width: int = 32):
        self.cfg = cfg
        self.chunk = chunk  # live prefixes per frame
        self.slice_size = slice_size  # children stepped per turn (a round of search_many: width x this)
        self.buckets = tuple(sorted(buckets))
        self.width = width  # concepts explored at once by search_many (bank slots)
        self._compiled: set[tuple] = set()
        self.compile_seconds = 0.0  # first calls of each (op, size): compile time, kept apart
        self._bank: tuple[SceneConst, Target] | None = None
        self._slot: dict[int, int] = {}  # id(task) -> bank slot

    # ---- the bank of concepts' scenes ----------------------------------------------------
    def _load(self, slot: int, task: Task) -> None:
        """Put a task's scenes and targets in a bank slot (a new bank if the example count
        differs from the current one's)."""
        e = task.n_examples
        if self._bank is None or self._bank[0].n.shape[1] != e:
            self._bank = jax.tree.map(lambda a: jnp.broadcast_to(a, (self.width,) + a.shape),
                                      (task.consts, task.targets))
            self._slot = {}
        self._bank = jax.tree.map(lambda b, a: b.at[slot].set(a), self._bank, (task.consts, task.targets))
        self._slot = {k: v for k, v in self._slot.items() if v != slot}
        self._slot[id(task)] = slot

    # ---- device stepping ------------------------------------------------------------
    def _padded(self, key, n: int, call):
        """Run `call(idx)` over 0..n-1 in bucket-sized pieces (the last piece padded by
        repeating its first row); time first calls of a (key, size) as compile time."""
        outs, start = [], 0
        while start < n:
            size = next((b for b in self.buckets if b >= n - start), self.buckets[-1])
            take = min(size, n - start)
            idx = np.arange(start, start + take)
            pad = np.concatenate([idx, np.full(size - take, idx[0])])
            first = (key, size) not in self._compiled
            t0 = time.perf_counter()
            out = jax.tree.map(lambda a: np.asarray(a)[:take], call(pad))
            if first:
                self._compiled.add((key, size))
                self.compile_seconds += time.perf_counter() - t0
            outs.append(out)
            start += take
        return _concat(outs)

    @staticmethod
    def _holding_parts(op: int, held: np.ndarray) -> list[np.ndarray]:
        """Rows of a group split into those where some example holds an object and the
        rest, for a carry op (the rest then skip the carry: `emulator.EMPTY_HANDED`)."""
        if op not in EMPTY_HANDED:
            return [np.arange(len(held))]
        holding = (held >= 0).any(axis=1)
        return [part for part in (np.nonzero(holding)[0], np.nonzero(~holding)[0]) if len(part)]

    def _run_group(self, op: int, tids: np.ndarray, states, args: np.ndarray):
        parts = self._holding_parts(op, packed_field(states, "held", self.cfg))
        if len(parts) == 1:
            return self._run_part(op, tids, states, args)
        outs = [(idx, self._run_part(op, tids[idx], _take(states, idx), args[idx])) for idx in parts]
        merged = jax.tree.map(lambda a: np.empty((len(args),) + a.shape[1:], a.dtype), outs[0][1])
        for idx, out in outs:
            jax.tree.map(lambda dst, src: dst.__setitem__(idx, src), merged, out)  # noqa: B023
        return merged

    def _run_part(self, op: int, tids: np.ndarray, states, args: np.ndarray):
        cfg, (consts, _) = self.cfg, self._bank
        loop_end = op == OP["loop_end"]
        new, failed = self._padded(
            ("step", op, states.shape[1]), len(args),
            lambda pad: advance(cfg, op, consts, jnp.asarray(tids[pad]), _take(states, pad),
                                jnp.asarray(args[pad]), not loop_end))
        if not loop_end:
            return new, failed
        self._replay(tids, new)
        return new, packed_field(new, "failed", cfg).any(axis=1)

    def _replay(self, tids: np.ndarray, states) -> None:
        """A closed loop's remaining iterations, one body instruction at a time, each
        group of programs stepped with that instruction's code only (in place)."""
        cfg = self.cfg
        body = unpack_state(states, cfg)  # the body is fixed once the loop is closed
        ops, args = body.body_ops[:, 0].copy(), body.body_args[:, 0].copy()
        length, pc0 = body.body_len[:, 0].copy(), body.body_pc0[:, 0].copy()
        iteration = 1
        while True:
            active = loop_needs_iteration(cfg, unpack_state(states, cfg), iteration)  # host: (n, E)
            rows_any = active.any(axis=1)
            if not rows_any.any():
                return
            for j in range(int(length[rows_any].max())):
                live = rows_any & (length > j)
                for op in np.unique(ops[live, j]):
                    group = np.nonzero(live & (ops[:, j] == op))[0]
                    for part in self._holding_parts(int(op), packed_field(states[group], "held", cfg)):
                        self._replay_rows(tids, states, int(op), group[part], args, pc0, active, j)
            iteration += 1

    def _replay_rows(self, tids, states, op: int, rows: np.ndarray, args, pc0, active, j: int) -> None:
        cfg, (consts, _) = self.cfg, self._bank
        sub = _take(states, rows)
        act, tr = active[rows], tids[rows]
        new = self._padded(
            ("replay", op, act.shape[1]), len(rows),
            lambda pad: replay(cfg, op, consts, jnp.asarray(tr[pad]), _take(sub, pad),
                                        jnp.asarray(args[rows][pad, j]), jnp.asarray(pc0[rows][pad] + j),
                                        jnp.asarray(act[pad])))
        jax.tree.map(lambda dst, src: dst.__setitem__(rows, src), states, new)

    # ---- the backend: what the DFS needs from a machine --------------------------------
    def root_states(self, task: Task):
        row = np.asarray(pack_state(init_state(self.cfg), self.cfg))
        return np.broadcast_to(row, (1, task.n_examples) + row.shape).copy()

    def take(self, states, idx: np.ndarray):
        return _take(states, idx)

    def prepare(self, tasks: Sequence[Task]) -> None:
        """Make room for these tasks (at most `width`) in the bank."""
        for slot, task in enumerate(tasks):
            self._load(slot, task)

    def admit(self, task: Task, active: Sequence[Task]) -> None:
        """A task joins the ones being explored (search_many): it takes a free slot."""
        used = {self._slot.get(id(t)) for t in active}
        self._load(next(k for k in range(self.width) if k not in used), task)

    def apply(self, chain: Chain, task: Task, states, portions: np.ndarray, may_end: np.ndarray):
        """Run each child's portion (one or more atoms) from its parent's state; return the
        states, whether each failed on some example, and, for children that `may_end` (a
        complete program under the cutoff), whether it explains every example."""
        return self.apply_many([(chain, task, states, portions, may_end)])[0]

    def apply_many(self, requests: Sequence[tuple]) -> list[tuple]:
        """`apply` for several (chain, task, states, portions, may_end) requests at once:
        their rows are stepped together, one group per instruction across all requests,
        and the rows that may end are judged together."""
        sizes = [len(r[3]) for r in requests]
        owner = np.repeat(np.arange(len(requests)), sizes)
        states = requests[0][2] if len(requests) == 1 else _concat([r[2] for r in requests])
        tids = np.array([self._slot[id(requests[i][1])] for i in owner], np.int32)
        rows_ops = [r[0].ops[z] for r in requests for z in r[3]]
        rows_args = [r[0].args[z] for r in requests for z in r[3]]
        n = len(owner)
        e = states.shape[1]
        failed = np.zeros(n, bool)
        lengths = np.array([len(o) for o in rows_ops])
        for k in range(int(lengths.max())):
            ops = np.array([o[k] if lengths[i] > k else -1 for i, o in enumerate(rows_ops)])
            args = np.array([a[k] if lengths[i] > k else 0 for i, a in enumerate(rows_args)], np.int32)
            for op in np.unique(ops[(ops >= 0) & ~failed]):
                rows = np.nonzero((ops == op) & ~failed)[0]
                new, f = self._run_group(int(op), tids[rows], _take(states, rows), args[rows])
                states[rows] = new
                failed[rows] |= f
        verdicts = np.zeros((n, e), np.int32)
        judged = np.nonzero(np.concatenate([r[4] for r in requests]) & ~failed)[0]
        if len(judged):
            cfg, (consts, targets) = self.cfg, self._bank
            verdicts[judged] = self._padded(
                ("judge", e), len(judged),
                lambda pad: judge(cfg, consts, targets, jnp.asarray(tids[judged][pad]), states[judged][pad]))
        ok = ~failed & np.all(verdicts == YES, axis=1)
        for i in np.nonzero(~failed & ~ok & np.all((verdicts == YES) | (verdicts == ASK), axis=1))[0]:
            ok[i] = self._settle(requests[owner[i]][1], states, int(i), verdicts[i])
        bounds = np.cumsum([0] + sizes)
        return [(states[a:b], failed[a:b], ok[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]

    def _settle(self, task: Task, states, i: int, v: np.ndarray) -> bool:
        """Rare: two same-looking objects within tau of one target; match on the host."""
        for e, (_, out) in enumerate(task.pairs):
            if v[e] == ASK:
                c = jax.tree.map(lambda a: a[e], task.consts)
                s = unpack_state(states[i, e], self.cfg)
                if not scenes_match(output_scene(c, s, self.cfg), out, self.cfg.tau):
                    return False
        return True

    # ---- the search -------------------------------------------------------------------
    def search(self, chain: Chain, task: Task, budget: int,
               progress: Callable[[int], None] | None = None) -> Result:
        """The shortest program under the budget's cutoff that explains every example."""
        t0 = time.perf_counter()
        c0 = self.compile_seconds
        self.prepare([task])
        dfs = self._dfs(chain, task, budget, progress)
        try:
            request = next(dfs)
            while True:
                request = dfs.send(self.apply(*request))
        except StopIteration as stop:
            found = stop.value
        return self._result(chain, budget, found, time.perf_counter() - t0, self.compile_seconds - c0)

    def search_many(self, jobs: Sequence[tuple[Chain, Task]], budget: int,
                    done: Callable[[int, Result], None]) -> None:
        """Explore every (chain, task) job, `width` at a time in lockstep; `done(index,
        result)` is called as each finishes (in finishing order). A job's `seconds` and
        `compile_seconds` are its share, by rows stepped, of the rounds it took part in."""
        queue = list(range(len(jobs)))
        active: dict[int, list] = {}  # job -> [coroutine, pending request, seconds, compile seconds]

        def start(j: int) -> None:
            chain, task = jobs[j]
            t0 = time.perf_counter()
            self.admit(task, [jobs[k][1] for k in active])
            dfs = self._dfs(chain, task, budget, None)
            try:
                active[j] = [dfs, next(dfs), time.perf_counter() - t0, 0.0]
            except StopIteration as stop:  # nothing under the cutoff to run
                done(j, self._result(chain, budget, stop.value, time.perf_counter() - t0, 0.0))

        while queue or active:
            while queue and len(active) < self.width:
                j = queue.pop(0)
                if active and jobs[j][1].n_examples != jobs[next(iter(active))][1].n_examples:
                    queue.insert(0, j)  # another example count: after the current ones finish
                    break
                start(j)
            if not active:
                continue
            t0, c0 = time.perf_counter(), self.compile_seconds
            order = list(active)
            replies = self.apply_many([active[j][1] for j in order])
            wall, comp = time.perf_counter() - t0, self.compile_seconds - c0
            rows = np.array([len(active[j][1][3]) for j in order], float)
            for j, reply, share in zip(order, replies, rows / rows.sum()):
                entry = active[j]
                t1 = time.perf_counter()
                try:
                    entry[1] = entry[0].send(reply)
                    entry[2] += wall * share + time.perf_counter() - t1
                    entry[3] += comp * share
                except StopIteration as stop:
                    del active[j]
                    seconds = entry[2] + wall * share + time.perf_counter() - t1
                    done(j, self._result(jobs[j][0], budget, stop.value, seconds, entry[3] + comp * share))

    def _result(self, chain: Chain, budget: int, found, seconds: float, compile_seconds: float) -> Result:
        best, nodes, programs, b_star, table = found
        if best is None:
            return Result(False, None, None, None, None, None, nodes, programs, seconds, b_star, budget,
                          compile_seconds)
        portions = [int(x) for x in best[1] if x >= 0]
        return Result(
            True, self.program(chain, portions), self.text(chain, portions),
            chain.program_nats(portions), best[0], int(table[best[0] - 1]) + 1 if best[0] > 0 else 1,
            nodes, programs, seconds, b_star, budget, compile_seconds,
        )

    def _dfs(self, chain: Chain, task: Task, budget: int,
             progress: Callable[[int], None] | None) -> Generator[tuple, tuple, tuple]:
        """The depth-first search as a coroutine: yields (chain, task, states, portions, may_end) to
        be applied, receives `apply`'s answer; returns (best, nodes, programs, b*, table)."""
        b_star, table = cutoff_for_budget(chain, budget)
        below = int(table[b_star - 1]) if b_star > 0 else 0
        quota = budget - below  # programs of cost exactly b* still allowed
        cutoff = b_star
        frames = [_Frame(self.root_states(task), np.array([chain.end]), np.array([NOT_STARTED]), np.array([0]),
                         np.full((1, MAX_PORTIONS), -1, np.int32), 0)]
        nodes = programs = 0
        best: tuple[int, np.ndarray] | None = None
        end_bins = chain.trans_bins[:, chain.end]
        while frames:
            fr = frames[-1]
            if fr.kids is None:
                fr.kids = self._children(chain, fr, cutoff)
            parent, z, cost, bound = fr.kids
            keep = np.nonzero(bound[fr.pos :] <= cutoff)[0] + fr.pos  # the cutoff may have dropped
            if len(keep) == 0:
                frames.pop()
                continue
            sl = keep[: self.slice_size]
            fr.pos = int(sl[-1]) + 1
            p, zz, cc = parent[sl], z[sl], cost[sl]
            tok = chain.tok[zz]
            syn = chain.next_syn[tok, fr.syn[p]]
            total = cc + end_bins[tok]
            may_end = (syn == OUTSIDE) & (total <= cutoff)
            states, failed, ok = yield (chain, task, self.take(fr.states, p), zz, may_end)
            nodes += len(sl)
            hist = fr.hist[p].copy()
            if fr.depth < MAX_PORTIONS:
                hist[:, fr.depth] = zz
            complete = ~failed & may_end
            for i in np.nonzero(complete)[0]:
                if total[i] == b_star:
                    if quota <= 0:
                        continue
                    quota -= 1
                    if quota == 0:
                        cutoff = min(cutoff, b_star - 1)
                programs += 1
                if ok[i] and (best is None or total[i] < best[0]):
                    best = (int(total[i]), hist[i].copy())
                    cutoff = min(cutoff, int(total[i]) - 1)
            if progress:
                progress(len(sl))
            live = ~failed & (cc + chain.min_rest[tok, np.maximum(syn, 0)] <= cutoff) & (syn >= 0)
            if fr.depth + 1 < MAX_PORTIONS:
                for part in np.array_split(np.nonzero(live)[0], max(1, -(-int(live.sum()) // self.chunk))):
                    if len(part):
                        frames.append(_Frame(self.take(states, part), tok[part], syn[part], cc[part],
                                             hist[part], fr.depth + 1))
        return best, nodes, programs, b_star, table

    def _children(self, chain: Chain, fr: _Frame, cutoff: int):
        cost = fr.cost[:, None] + chain.trans_bins[fr.last[:, None], chain.tok[None, :]] + chain.argbins[None, :]
        syn = chain.next_syn[chain.tok[None, :], fr.syn[:, None]]
        bound = cost + chain.min_rest[chain.tok[None, :], np.maximum(syn, 0)]
        parent, z = np.nonzero((syn >= 0) & (bound <= cutoff))
        order = np.argsort(cost[parent, z], kind="stable")  # the most probable children first
        parent, z = parent[order], z[order]
        return parent, z, cost[parent, z], bound[parent, z]

    @staticmethod
    def program(chain: Chain, portions: Sequence[int]) -> Program:
        ops = tuple(o for z in portions for o in chain.ops[z])
        args = tuple(a for z in portions for a in chain.args[z])
        return Program(ops, args)

    @staticmethod
    def text(chain: Chain, portions: Sequence[int]) -> str:
        parts = []
        for z in portions:
            t = int(chain.tok[z])
            vals = [arg_domain(NAMES[o])[a] for o, a in zip(chain.ops[z], chain.args[z]) if arg_domain(NAMES[o])]
            name = chain.vocab.name(t)
            parts.append(f"{name}({', '.join(vals)})" if vals else name)
        return "; ".join(parts)
