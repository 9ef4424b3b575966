"""The search's backend on the JAX emulator: many concepts' children stepped together,
one device call per piece of a round's rows.

The concepts being searched have their example scenes and targets in a bank of
`width` slots on each device (a fixed shape: each instruction compiles once whatever the
number of concepts); a batch's rows are programs, each reading its concept's slot in
the bank of the device its piece was dealt to (`search.device_calls`).
On the host a prefix's states are one packed int32 row per example (`search.packing`),
so a frame is one array and a transfer one copy. A round's children, whatever their
instructions, are stepped by all their atoms (a subroutine is several, in turn) with
the further iterations of the loops they close in one device call per piece of rows
(`stepping.advance_atoms`: rows of one instruction taken a few at a time through one
switch; a portion longer than `ATOM_COLUMNS` atoms takes a call per further group), so
a round makes one call where it made one per atom position (and before that one per
instruction), and one function compiles. Complete programs are judged on
the device.

This module is the only part of the search that reads the machine state's fields
(the section "the machine state's fields" below).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import jax
import jax.numpy as jnp
import numpy as np

from search.backend import Reply, Request
from search.device_calls import BUCKETS, DeviceCalls
from search.packing import blackboard_columns, pack_state, unpack_blackboard, unpack_state
from search.stepping import advance_atoms
from search.task import Task
from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.match import ASK, YES, Target, verdict
from vccjax.machine.scene import scenes_match
from vccjax.machine.state import SceneConst, VCCState, init_state, output_scene

# One batch size for the step (with its replay): its cost follows the rows it runs, not
# the padding (only copied), so one compile serves every round. A call steps up to
# ATOM_COLUMNS atoms of each row (a longer portion takes another call): a fixed shape too,
# and columns no row reaches cost nothing.
STEP_ROWS = (256,)
ATOM_COLUMNS = 8


# ---- the machine state's fields: the only places the search reads them ----------------
def _failed_anywhere(states: VCCState) -> jax.Array:
    """(B,) whether each program of (B, E) states failed on some example (traced)."""
    return jnp.any(states.control.failed, axis=1)


def _blackboards(packed: np.ndarray, cfg: VCCConfig) -> np.ndarray:
    """The leading columns of packed rows that output matching reads."""
    return packed[:, :, : blackboard_columns(cfg)]


# ---- device functions ---------------------------------------------------------------
@functools.partial(jax.jit, static_argnums=0)
def _device_verdicts(cfg: VCCConfig, consts: SceneConst, targets: Target, slots, boards):
    """Verdicts (B, E) of packed states (their blackboard columns suffice), row b against
    the outputs of the task in bank slot `slots[b]`."""
    def row(slot, s):
        c, t = jax.tree.map(lambda a: a[slot], (consts, targets))
        return jax.vmap(functools.partial(verdict, cfg))(c, s, t)

    return jax.vmap(row)(slots, unpack_blackboard(boards, cfg))


@functools.partial(jax.jit, static_argnums=0)
def _advance_packed(cfg: VCCConfig, consts: SceneConst, slots, packed, ops, args, real):
    """`stepping.advance_atoms` on packed states, the first `real` rows; return the states
    and whether each program failed on any example."""
    new = advance_atoms(cfg, consts, slots, unpack_state(packed, cfg), ops, args, real)
    return pack_state(new, cfg), _failed_anywhere(new)


@functools.lru_cache(maxsize=None)
def _packed_root(cfg: VCCConfig) -> np.ndarray:
    return np.asarray(pack_state(init_state(cfg), cfg))


@functools.partial(jax.jit, donate_argnums=0)
def _put_in_slot(bank, slot, item):
    """`item` into slot `slot` of every leaf of `bank` (one compiled update, not one per leaf)."""
    return jax.tree.map(lambda b, a: b.at[slot].set(a), bank, item)


def _columns(m: np.ndarray, fill: int) -> np.ndarray:
    """The first ATOM_COLUMNS columns of (n, k) `m`, padded with `fill`."""
    out = np.full((len(m), ATOM_COLUMNS), fill, m.dtype)
    width = min(ATOM_COLUMNS, m.shape[1])
    out[:, :width] = m[:, :width]
    return out


def _atoms(requests: Sequence[Request]) -> tuple[np.ndarray, np.ndarray]:
    """Every child's portion as atoms: ops (n, atoms) -1 padded, args (n, atoms) 0 padded."""
    atoms = max(r.chain.op_mat.shape[1] for r in requests)

    def padded(m: np.ndarray) -> np.ndarray:
        return np.pad(m, ((0, 0), (0, atoms - m.shape[1])), constant_values=-1)

    ops = np.concatenate([padded(r.chain.op_mat[r.portions]) for r in requests])
    args = np.maximum(np.concatenate([padded(r.chain.arg_mat[r.portions]) for r in requests]), 0)
    return ops, args


class JaxBackend:
    """The `search.backend.Backend` on the JAX emulator; one instance keeps its compiled
    steps and its bank of up to `width` tasks."""

    def __init__(self, cfg: VCCConfig = DEFAULT_CONFIG, buckets: Sequence[int] = BUCKETS,
                 width: int = 32, devices: Sequence[jax.Device] | None = None):
        self.cfg = cfg
        self.calls = DeviceCalls(buckets, devices)  # every batch's pieces dealt out to these devices
        self.width = width  # bank slots: tasks run at once
        self._bank: dict[jax.Device, tuple[SceneConst, Target]] = {}  # (width, E, ...) on each device
        self._bank_examples = 0  # E of the bank
        self._slot_of: dict[int, int] = {}  # id(task) -> bank slot
        self._room: np.ndarray | None = None  # see `_children_room`

    @property
    def compile_seconds(self) -> float:
        return self.calls.compile_seconds

    # ---- the backend interface ----------------------------------------------------------
    def root_states(self, task: Task) -> np.ndarray:
        root = _packed_root(self.cfg)
        return np.broadcast_to(root, (1, task.n_examples) + root.shape).copy()

    def take(self, states: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return states[rows]

    def join(self, parts: Sequence[np.ndarray]) -> np.ndarray:
        return np.concatenate(parts)

    def admit(self, task: Task, alongside: Sequence[Task]) -> None:
        """`task` takes the first bank slot that none of `alongside` holds."""
        used = {self._slot_of.get(id(t)) for t in alongside}
        self._load(next(k for k in range(self.width) if k not in used), task)

    def apply_many(self, requests: Sequence[Request]) -> list[Reply]:
        """Every request's children stepped together by all their atoms (up to ATOM_COLUMNS
        atoms per call, whatever their instructions); then the children that may end
        judged together."""
        sizes = [len(r.portions) for r in requests]
        bounds = np.cumsum([0] + sizes)
        owner = np.repeat(np.arange(len(requests)), sizes)  # (n,) the request of each child
        parents, parent_row = self._parents(requests)
        children = self._children_room((len(owner),) + parents.shape[1:], parents.dtype)  # filled by the calls
        slots = np.array([self._slot_of[id(r.task)] for r in requests], np.int32)[owner]
        ops, args = _atoms(requests)
        failed = np.zeros(len(owner), bool)
        for k in range(0, ops.shape[1], ATOM_COLUMNS):  # every child's atoms k.. (portions are -1 padded)
            source, source_row = (parents, parent_row) if k == 0 else (children, np.arange(len(owner)))
            self._step_atoms(_columns(ops[:, k:], -1), _columns(args[:, k:], 0), slots, source, source_row,
                             children, failed)
        may_end = np.concatenate([r.may_end for r in requests])
        solved = self._judge(requests, owner, slots, children, np.nonzero(may_end & ~failed)[0], failed)
        return [Reply(children[a:b], failed[a:b], solved[a:b]) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]

    # ---- the bank of tasks' scenes ---------------------------------------------------------
    def _load(self, slot: int, task: Task) -> None:
        """Put a task's scenes and targets in a bank slot (a new bank if the example count
        differs from the current one's)."""
        if not self._bank or self._bank_examples != task.n_examples:
            empty = jax.tree.map(lambda a: jnp.broadcast_to(a, (self.width,) + a.shape), (task.consts, task.targets))
            self._bank = {d: jax.device_put(empty, d) for d in self.calls.devices}
            self._bank_examples = task.n_examples
            self._slot_of = {}
        for d, bank in self._bank.items():
            self._bank[d] = _put_in_slot(bank, slot, jax.device_put((task.consts, task.targets), d))
        self._slot_of = {k: v for k, v in self._slot_of.items() if v != slot}
        self._slot_of[id(task)] = slot

    # ---- stepping -------------------------------------------------------------------------
    @staticmethod
    def _parents(requests: Sequence[Request]) -> tuple[np.ndarray, np.ndarray]:
        """The states the children start from, each parent once (a frame's parent has many
        children spread over many rounds: copying a state per child would copy it many
        times), and each child's row in them."""
        states, rows, offset = [], [], 0
        for r in requests:
            used, row = np.unique(r.parents, return_inverse=True)
            states.append(r.states[used])
            rows.append(row.reshape(-1) + offset)
            offset += len(used)
        return np.concatenate(states), np.concatenate(rows)

    def _step_atoms(self, ops: np.ndarray, args: np.ndarray, slots: np.ndarray, source: np.ndarray,
                    source_row: np.ndarray, children: np.ndarray, failed: np.ndarray) -> None:
        """Step each child not yet failed by its atoms `ops[i]` (ATOM_COLUMNS of them, -1
        where none) in turn, from state `source[source_row[i]]` into `children[i]`, closed
        loops' further iterations included; mark `failed` (both in place). One device call
        per piece of `STEP_ROWS` rows (`stepping.advance_atoms`)."""
        rows = np.nonzero((ops[:, 0] >= 0) & ~failed)[0]
        if len(rows) == 0:
            return
        cfg, bank = self.cfg, self._bank
        pending = self.calls.start(
            ("advance", source.shape[1]), rows,
            lambda rows_of: _advance_packed(cfg, bank[rows_of.device][0], rows_of(slots), rows_of(source, source_row),
                                            rows_of(ops), rows_of(args), rows_of.real),
            STEP_ROWS)
        for piece, (new, fails) in self.calls.results(pending):
            children[piece] = new
            failed[piece] |= fails

    def _children_room(self, shape: tuple, dtype) -> np.ndarray:
        """Room for a round's children, reused from round to round (a fresh array each round
        cost as much in page faults as the copies into it). The search copies what it keeps
        (`take`) before the next round, so nothing outlives the round."""
        size = int(np.prod(shape))
        if self._room is None or self._room.size < size or self._room.dtype != dtype:
            self._room = np.empty(max(size, 2 * (0 if self._room is None else self._room.size)), dtype)
        return self._room[:size].reshape(shape)

    # ---- judging --------------------------------------------------------------------------
    def _judge(self, requests: Sequence[Request], owner: np.ndarray, slots: np.ndarray, children: np.ndarray,
               judged: np.ndarray, failed: np.ndarray) -> np.ndarray:
        """(n,) whether each child explains every example of its task: rows `judged` on the
        device (YES / NO / ASK), an ASK settled on the host."""
        cfg, examples = self.cfg, children.shape[1]
        verdicts = np.zeros((len(children), examples), np.int32)
        if len(judged):
            bank, boards = self._bank, _blackboards(children, cfg)
            for rows, found in self.calls.run(
                    ("judge", examples), judged,
                    lambda rows_of: _device_verdicts(cfg, *bank[rows_of.device], rows_of(slots), rows_of(boards))):
                verdicts[rows] = found
        solved = ~failed & np.all(verdicts == YES, axis=1)
        for i in np.nonzero(~failed & ~solved & np.all((verdicts == YES) | (verdicts == ASK), axis=1))[0]:
            solved[i] = self._settle(requests[owner[i]].task, children, int(i), verdicts[i])
        return solved

    def _settle(self, task: Task, states: np.ndarray, row: int, verdicts: np.ndarray) -> bool:
        """Rare: two same-looking objects within tau of one target; match on the host."""
        for e, (_, output) in enumerate(task.pairs):
            if verdicts[e] == ASK:
                consts = jax.tree.map(lambda a: a[e], task.consts)  # noqa: B023
                state = unpack_state(states[row, e], self.cfg)
                if not scenes_match(output_scene(consts, state, self.cfg), output, self.cfg.tau):
                    return False
        return True
