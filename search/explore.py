"""Exploration: enumerate every program under a description-length cutoff, batched.

Depth-first over chunks of the frontier (memory stays bounded by depth x chunk): a
frame holds up to `chunk` live prefixes with their emulator states on all examples;
its children (prefix + one portion) are made in slices, grouped by instruction, and
stepped with `step_examples`, so every group runs one instruction's code over
(programs x examples) at once. A child that fails on any example is dropped with its
whole subtree (docs/vcc.md section 3). A child that may end is a complete program: it is
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
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding
from jax.sharding import PartitionSpec as P

from search.chain import NOT_STARTED, OUTSIDE, Chain, cutoff_for_budget
from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.match import ASK, YES, Target, load_target, verdict
from vccjax.machine.instructions import NAMES, OP, arg_domain
from vccjax.machine.program import Program
from vccjax.machine.scene import Scene, scenes_match
from vccjax.machine.state import SceneConst, init_state, load_scene, output_scene, stack

from search.packing import blackboard_columns, pack_state, packed_field, unpack_blackboard, unpack_state
from search.stepping import EMPTY_HANDED, loop_needs_iteration, replay_examples, step_examples

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
    """Verdicts (B, E) of packed states (their blackboard columns suffice), row b against
    task `tasks[b]`'s outputs."""
    def row(task, s):
        c, t = jax.tree.map(lambda a: a[task], (consts, targets))
        return jax.vmap(functools.partial(verdict, cfg))(c, s, t)

    return jax.vmap(row)(tasks, unpack_blackboard(packed, cfg))


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


@functools.lru_cache(maxsize=None)
def _root_row(cfg: VCCConfig) -> np.ndarray:
    return np.asarray(pack_state(init_state(cfg), cfg))


CALL_ROWS = 8  # a device call's fixed cost, in rows stepped


@functools.lru_cache(maxsize=8192)
def _cover(n: int, buckets: tuple[int, ...]) -> tuple[int, ...]:
    """The cheapest multiset of buckets holding n rows (n < the largest bucket)."""
    best = [(0, ())] + [None] * n  # rows -> (cost, pieces)
    for m in range(1, n + 1):
        best[m] = min((CALL_ROWS + b + best[max(m - b, 0)][0], (b,) + best[max(m - b, 0)][1]) for b in buckets)
    return best[n][1]


@functools.partial(jax.jit, donate_argnums=0)
def _put(bank, slot, item):
    """`item` into slot `slot` of every leaf of `bank` (one compiled update, not one per leaf)."""
    return jax.tree.map(lambda b, a: b.at[slot].set(a), bank, item)


class Request(NamedTuple):
    """What a concept's search asks the machine to run: each child is its parent's state
    (`states[parents[i]]`) stepped by one portion; `may_end` marks complete programs to judge."""

    chain: Chain
    task: Task
    states: object  # the frame's states (packed array for Explorer)
    parents: np.ndarray
    portions: np.ndarray
    may_end: np.ndarray


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
                 buckets: Sequence[int] = (16, 64, 256, 1024, 4096), width: int = 32,
                 devices: Sequence[jax.Device] | None = None):
        self.cfg = cfg
        # every batch is split by rows over these devices (the bank of scenes is copied to each)
        self.devices = list(devices) if devices is not None else jax.devices()
        if any(b % len(self.devices) for b in buckets):
            raise ValueError(f"batch sizes {tuple(buckets)} must divide over {len(self.devices)} devices")
        mesh = Mesh(np.array(self.devices), ("rows",))
        self._rows, self._everywhere = NamedSharding(mesh, P("rows")), NamedSharding(mesh, P())
        self.chunk = chunk  # live prefixes per frame
        self.slice_size = slice_size  # children stepped per turn (a round of search_many: width x this)
        self.buckets = tuple(sorted(buckets))
        self.width = width  # concepts explored at once by search_many (bank slots)
        self._compiled: set[tuple] = set()
        self.compile_seconds = 0.0  # first calls of each (op, size): compile time, kept apart
        self._bank: tuple[SceneConst, Target] | None = None
        self._slot: dict[int, int] = {}  # id(task) -> bank slot
        self._room: np.ndarray | None = None  # see `_buffer`

    # ---- the bank of concepts' scenes ----------------------------------------------------
    def _load(self, slot: int, task: Task) -> None:
        """Put a task's scenes and targets in a bank slot (a new bank if the example count
        differs from the current one's)."""
        e = task.n_examples
        if self._bank is None or self._bank[0].n.shape[1] != e:
            self._bank = jax.device_put(jax.tree.map(lambda a: jnp.broadcast_to(a, (self.width,) + a.shape),
                                                     (task.consts, task.targets)), self._everywhere)
            self._slot = {}
        self._bank = _put(self._bank, slot, jax.device_put((task.consts, task.targets), self._everywhere))
        self._slot = {k: v for k, v in self._slot.items() if v != slot}
        self._slot[id(task)] = slot

    # ---- device stepping ------------------------------------------------------------
    def _dispatch(self, key, rows: np.ndarray, call) -> list:
        """Start `call(at)` over `rows` in bucket-sized pieces (each padded by repeating its
        first row; `at(a)` gives a host array's rows of the piece) without waiting for the
        results: JAX runs them while the host prepares the next. First calls of a
        (key, size) compile synchronously and are timed as compile time. Returns
        [(rows of the piece, device outputs with the padding)], for `_collect`."""
        start, pending = 0, []
        for size in self._pieces(len(rows)):
            idx = rows[start : start + size]
            pad = np.concatenate([idx, np.full(size - len(idx), idx[0])])
            first = (key, size) not in self._compiled
            t0 = time.perf_counter()
            pending.append((idx, call(self._rows_of(pad))))
            if first:
                jax.block_until_ready(pending[-1][1])
                self._compiled.add((key, size))
                self.compile_seconds += time.perf_counter() - t0
            start += size
        return pending

    @staticmethod
    def _collect(pending: list):
        """(rows, host outputs without the padding) of dispatched pieces, waiting for each."""
        for idx, out in pending:
            yield idx, jax.tree.map(lambda a: np.asarray(a)[: len(idx)], out)  # noqa: B023

    def _pieces_of(self, key, rows: np.ndarray, call):
        """`_dispatch` and `_collect` at once."""
        return self._collect(self._dispatch(key, rows, call))

    def _rows_of(self, pad: np.ndarray) -> Callable[..., object]:
        """What `call` gets: `at(a)`, the padded rows of a host array (`at(a, via)`: rows
        `via[pad]` of it), split over the devices by rows when there are several (XLA then
        runs each device's share)."""
        def at(a: np.ndarray, via: np.ndarray | None = None):
            rows = a[pad if via is None else via[pad]]
            return rows if len(self.devices) == 1 else jax.device_put(rows, self._rows)
        return at

    def _pieces(self, n: int) -> list[int]:
        """Bucket sizes covering n rows at the least cost, counting each call as
        CALL_ROWS rows of fixed overhead plus its padded rows (one 1024 call for 300 rows
        wastes more than a 256 and a 64 cost)."""
        big = self.buckets[-1]
        full, rest = divmod(n, big)
        return [big] * full + (list(_cover(rest, self.buckets)) if rest else [])

    def _holding_parts(self, op: int, source, at: np.ndarray, rows: np.ndarray) -> list[np.ndarray]:
        """`rows` split into those where some example holds an object (their states are
        `source[at]`) and the rest, for a carry op (the rest then skip the carry:
        `emulator.EMPTY_HANDED`)."""
        if op not in EMPTY_HANDED:
            return [rows]
        holding = (packed_field(source, "held", self.cfg)[at] >= 0).any(axis=1)
        return [part for part in (rows[holding], rows[~holding]) if len(part)]

    def _dispatch_step(self, op: int, tids: np.ndarray, source, src: np.ndarray, rows: np.ndarray,
                       args: np.ndarray) -> list:
        """Start stepping rows `rows` of the batch by `op`, row i's state being
        `source[src[i]]` (packed, (n, E, P)); see `_dispatch`."""
        cfg, (consts, _) = self.cfg, self._bank
        replay_here = op != OP["loop_end"]  # a closed loop's further iterations: `_replay`
        pending = []
        for part in self._holding_parts(op, source, src[rows], rows):
            pending += self._dispatch(
                ("step", op, source.shape[1]), part,
                lambda at: advance(cfg, op, consts, at(tids), at(source, src), at(args), replay_here))
        return pending

    def _replay(self, tids: np.ndarray, states, rows: np.ndarray) -> None:
        """A closed loop's remaining iterations for `states[rows]`, one body instruction at a
        time, each group of programs stepped with that instruction's code only (in place)."""
        cfg = self.cfg
        body = unpack_state(states[rows], cfg)  # the body is fixed once the loop is closed
        ops, args = body.body_ops[:, 0], body.body_args[:, 0]
        length, pc0 = body.body_len[:, 0], body.body_pc0[:, 0]
        active = np.zeros(states.shape[:2], bool)  # (all rows, E)
        arg_j, pc_j = np.zeros(len(states), np.int32), np.zeros(len(states), np.int32)  # read at `rows` only
        iteration = 1
        while True:
            active[rows] = loop_needs_iteration(cfg, unpack_state(states[rows], cfg), iteration)  # host
            rows_any = active[rows].any(axis=1)
            if not rows_any.any():
                return
            for j in range(int(length[rows_any].max())):
                live = rows_any & (length > j)
                pending = []  # the groups of body position j, all started before any is waited for
                for op in np.unique(ops[live, j]):
                    local = np.nonzero(live & (ops[:, j] == op))[0]
                    arg_j[rows[local]], pc_j[rows[local]] = args[local, j], pc0[local] + j
                    for part in self._holding_parts(int(op), states, rows[local], rows[local]):
                        pending += self._dispatch_replay(tids, states, int(op), part, arg_j, pc_j, active)
                for idx, new in self._collect(pending):
                    states[idx] = new
            iteration += 1

    def _dispatch_replay(self, tids, states, op: int, rows: np.ndarray, args, pcs, active) -> list:
        cfg, (consts, _) = self.cfg, self._bank
        return self._dispatch(("replay", op, active.shape[1]), rows,
                              lambda at: replay(cfg, op, consts, at(tids), at(states), at(args), at(pcs), at(active)))

    # ---- the backend: what the DFS needs from a machine --------------------------------
    def root_states(self, task: Task):
        row = _root_row(self.cfg)
        return np.broadcast_to(row, (1, task.n_examples) + row.shape).copy()

    def take(self, states, idx: np.ndarray):
        return states[idx]

    def prepare(self, tasks: Sequence[Task]) -> None:
        """Make room for these tasks (at most `width`) in the bank."""
        for slot, task in enumerate(tasks):
            self._load(slot, task)

    def admit(self, task: Task, active: Sequence[Task]) -> None:
        """A task joins the ones being explored (search_many): it takes a free slot."""
        used = {self._slot.get(id(t)) for t in active}
        self._load(next(k for k in range(self.width) if k not in used), task)

    def apply(self, request: Request):
        """Run each child's portion (one or more atoms) from its parent's state; return the
        states, whether each failed on some example, and, for children that may end (a
        complete program under the cutoff), whether it explains every example."""
        return self.apply_many([request])[0]

    def apply_many(self, requests: Sequence[Request]) -> list[tuple]:
        """`apply` for several requests at once: their rows are stepped together, one group
        per instruction across all requests, and the rows that may end are judged together."""
        sizes = [len(r.portions) for r in requests]
        bounds = np.cumsum([0] + sizes)
        owner = np.repeat(np.arange(len(requests)), sizes)
        # the parents the children start from, each once (a frame's parent has many children
        # spread over many rounds: copying a state per child would copy it many times)
        used, where, base = [], [], 0
        for r in requests:
            u, inv = np.unique(r.parents, return_inverse=True)
            used.append(r.states[u])
            where.append(inv.reshape(-1) + base)
            base += len(u)
        parents, parent_of = np.concatenate(used), np.concatenate(where)
        n, e = len(owner), parents.shape[1]
        states = self._buffer((n,) + parents.shape[1:], parents.dtype)  # the children's, filled column by column
        tids = np.array([self._slot[id(r.task)] for r in requests], np.int32)[owner]
        width = max(r.chain.op_mat.shape[1] for r in requests)
        pad = lambda m: np.pad(m, ((0, 0), (0, width - m.shape[1])), constant_values=-1)  # noqa: E731
        op_rows = np.concatenate([pad(r.chain.op_mat[r.portions]) for r in requests])  # (n, atoms), -1 padded
        arg_rows = np.maximum(np.concatenate([pad(r.chain.arg_mat[r.portions]) for r in requests]), 0)
        failed = np.zeros(n, bool)
        for k in range(width):  # column k of the portions: every child's k-th atom (portions are -1 padded)
            ops, args = op_rows[:, k], np.ascontiguousarray(arg_rows[:, k])
            source, src = (parents, parent_of) if k == 0 else (states, np.arange(n))
            groups = {int(op): np.nonzero((ops == op) & ~failed)[0] for op in np.unique(ops[(ops >= 0) & ~failed])}
            pending = [self._dispatch_step(op, tids, source, src, rows, args) for op, rows in groups.items()]
            for piece in pending:  # every group started before any is waited for
                for idx, (new, f) in self._collect(piece):
                    states[idx] = new
                    failed[idx] |= f
            closed = groups.get(OP["loop_end"])
            if closed is not None:
                closed = closed[~failed[closed]]
                self._replay(tids, states, closed)
                failed[closed] |= packed_field(states, "failed", self.cfg)[closed].any(axis=1)
        verdicts = np.zeros((n, e), np.int32)
        judged = np.nonzero(np.concatenate([r.may_end for r in requests]) & ~failed)[0]
        if len(judged):
            cfg, (consts, targets) = self.cfg, self._bank
            boards = states[:, :, : blackboard_columns(cfg)]
            for idx, v in self._pieces_of(("judge", e), judged,
                                          lambda at: judge(cfg, consts, targets, at(tids), at(boards))):
                verdicts[idx] = v
        ok = ~failed & np.all(verdicts == YES, axis=1)
        for i in np.nonzero(~failed & ~ok & np.all((verdicts == YES) | (verdicts == ASK), axis=1))[0]:
            ok[i] = self._settle(requests[owner[i]].task, states, int(i), verdicts[i])
        return [(states[a:b], failed[a:b], ok[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]

    def _buffer(self, shape: tuple, dtype) -> np.ndarray:
        """Room for a round's children, reused from round to round (a fresh array each round
        cost as much in page faults as the copies into it). The DFS copies what it keeps
        (`take`) before the next round, so nothing outlives the round."""
        size = int(np.prod(shape))
        if self._room is None or self._room.size < size or self._room.dtype != dtype:
            self._room = np.empty(max(size, 2 * (0 if self._room is None else self._room.size)), dtype)
        return self._room[:size].reshape(shape)

    def _settle(self, task: Task, states, i: int, v: np.ndarray) -> bool:
        """Rare: two same-looking objects within tau of one target; match on the host."""
        for e, (_, out) in enumerate(task.pairs):
            if v[e] == ASK:
                c = jax.tree.map(lambda a: a[e], task.consts)  # noqa: B023
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
                request = dfs.send(self.apply(request))
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
            rows = np.array([len(active[j][1].portions) for j in order], float)
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
             progress: Callable[[int], None] | None) -> Generator[Request, tuple, tuple]:
        """The depth-first search as a coroutine: yields a `Request` to be applied, receives
        `apply`'s answer; returns (best, nodes, programs, b*, table)."""
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
            states, failed, ok = yield Request(chain, task, fr.states, p, zz, may_end)
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
