"""The search's batched stepping: many programs of many concepts, each on its concept's
example scenes, stepped together on the device.

A search holds (B, E) states, B programs times E examples. `advance_atoms` steps each
row by its own atoms in turn (a subroutine is several) and replays the loops each step
closes, a search round in one device call through one switch over the instructions.
`step_examples` steps all rows by one static op; with replay=False a `loop_end` only
closes the loop and `replay_loops` runs every further iteration in one call, each body
instruction by its own code only (`replay_examples`): the emulator benchmark's
per-instruction calls.
"""

from __future__ import annotations

import functools
from typing import Callable

import jax
import jax.numpy as jnp
import numpy as np

from vccjax.machine.config import VCCConfig
from vccjax.machine.instructions import OP
from vccjax.machine.ops import hand_to_attended, select
from vccjax.machine.state import SceneConst, VCCState
from vccjax.machine.step import after_op, before_op, execute, step_op


def _fails_empty_handed(cfg, c, s, arg):
    return s, jnp.bool_(True)


# Carrying is the costly part of a hand move, and it only happens with an object held:
# when no state in a batch holds one, these ops run a stand-in with the same outcome.
EMPTY_HANDED = {
    OP["move_hand_to_attended_object"]: functools.partial(hand_to_attended, carry=False),
    **{OP[f"move_hand_{d}"]: _fails_empty_handed for d in ("left", "right", "up", "down")},
    OP["move_hand_to_pointer"]: _fails_empty_handed,
    OP["move_hand_to_fixate_collision"]: _fails_empty_handed,
}


def holding_split(op: int, rows: np.ndarray, holding: np.ndarray,
                  piece_sizes: Callable[[int], list[int]]) -> list[np.ndarray]:
    """`rows` split into those where some example holds an object (`holding`, one bool per
    row) and the rest, for a carry op (the rest then skip the carry: `EMPTY_HANDED`),
    when that makes the carrying calls smaller: padded to the same sizes, the split
    would only add a call (the emulator benchmark's per-instruction calls; `advance_atoms`
    groups a carry op's holders apart on the device)."""
    if op not in EMPTY_HANDED or sum(piece_sizes(int(holding.sum()))) >= sum(piece_sizes(len(rows))):
        return [rows]
    return [part for part in (rows[holding], rows[~holding]) if len(part)]


def _batched(cfg: VCCConfig, op: int, make, first, states, *rest, stepped=True):
    """`make(fn)` builds the batched step `(first, states, *rest) -> states` with `fn`
    standing in for the op's function; a carry op pays for the carry only when some
    state it steps (`stepped`, a mask like `states.hand.held`, or all) holds an object."""
    if op not in EMPTY_HANDED:
        return make(None)(first, states, *rest)
    holding = (states.hand.held >= 0) & stepped
    return jax.lax.cond(jnp.any(holding), make(None), make(EMPTY_HANDED[op]), first, states, *rest)


def _per_task(consts: SceneConst, one, example_axes: tuple):
    """Rows of (B, E) states, each row a program of the task `tasks[row]`; `one` steps one
    (scene, state, ...) pair. The task's scenes are read by index, not copied per row."""

    def row(task, s, *rest):
        c = jax.tree.map(lambda a: a[task], consts)
        return jax.vmap(one, in_axes=(0, 0) + example_axes)(c, s, *rest)

    return jax.vmap(row)


@functools.partial(jax.jit, static_argnums=(0, 1, 6))
def step_examples(cfg: VCCConfig, op: int, consts: SceneConst, tasks: jax.Array, states: VCCState,
                  args: jax.Array, replay: bool = True) -> VCCState:
    """Step B programs' states on their tasks' E examples by one static op.

    consts: (K, E, ...) the examples' scenes of K tasks (concepts); tasks: (B,) which task
    each program belongs to; states: (B, E, ...); args: (B,). Programs of many concepts
    step in one call, so a search over many concepts makes large batches. With
    replay=False a `loop_end` only closes the loop: the caller replays the body
    with `replay_loops` (each body instruction by its own code, instead of every
    instruction's code in a traced loop)."""

    def per_program(fn):
        def one(c, s, arg):
            return step_op(cfg, c, s, op, arg, fn=fn, replay=replay)

        return _per_task(consts, one, (None,))

    return _batched(cfg, op, per_program, tasks, states, args)


def loop_needs_iteration(cfg: VCCConfig, s: VCCState, iteration) -> jax.Array:
    """Whether a just-closed loop runs another iteration (`iteration` = iterations done;
    docs/vcc.md section 5: while k < len(A), at most n_max in all, the first ran eagerly)."""
    ctl, a = s.control, s.attention
    return ctl.loop_active & ~ctl.failed & (iteration < cfg.n_max) & (a.cursor < a.attended_list_len)


@functools.partial(jax.jit, static_argnums=(0, 1))
def replay_examples(cfg: VCCConfig, op: int, consts: SceneConst, tasks: jax.Array, states: VCCState,
                    args: jax.Array, pcs: jax.Array, active: jax.Array) -> VCCState:
    """One body instruction of a replayed loop, static op, for states where `active`
    (B, E); the others are returned unchanged. consts, tasks as in `step_examples`;
    args, pcs: (B,)."""

    def per_program(fn):
        def one(c, s, arg, pc, act):
            return select(act & ~s.control.failed, execute(cfg, c, s, op, arg, pc, fn), s)

        return _per_task(consts, one, (None, None, 0))

    return _batched(cfg, op, per_program, tasks, states, args, pcs, active, stepped=active & ~states.control.failed)


REPLAY_CHUNK = 4  # rows a replayed instruction runs on at a time
_CARRIES = np.array([op in EMPTY_HANDED for op in range(len(OP))])  # ops whose cost is the carry


def by_instruction(s: VCCState, op: jax.Array, active: jax.Array, pending: jax.Array, size: int, run) -> VCCState:
    """Run the `pending` rows of (B, E) states `size` at a time, rows of one instruction
    (`op`, (B,)) together, a carry op's rows that hold an object (where `active`) apart:
    `run(rows' states, op, row indices, taken)` steps one gathered chunk (indices of
    untaken slots repeat the last row; their results are dropped)."""
    rows = op.shape[0]
    holds = jnp.any((s.hand.held >= 0) & active, axis=1)
    key = 2 * op + (holds & jnp.asarray(_CARRIES)[op])

    def chunk(carry):  # up to `size` pending rows of the least key
        s, pending = carry
        k = jnp.min(jnp.where(pending, key, 2 * len(OP)))
        at = jnp.nonzero(pending & (key == k), size=size, fill_value=rows)[0]
        safe = jnp.minimum(at, rows - 1)
        new = run(jax.tree.map(lambda a: a[safe], s), k // 2, safe, at < rows)
        s = jax.tree.map(lambda a, b: a.at[at].set(b, mode="drop"), s, new)
        return s, pending.at[at].set(False, mode="drop")

    return jax.lax.while_loop(lambda carry: jnp.any(carry[1]), chunk, (s, pending))[0]


@functools.partial(jax.jit, static_argnums=0)
def replay_loops(cfg: VCCConfig, consts: SceneConst, tasks: jax.Array, states: VCCState,
                 real: jax.Array | None = None) -> VCCState:
    """Every further iteration of the loops just closed in (B, E) states (a `loop_end`
    stepped with replay=False), in one device call: the host's replay of one call per
    (iteration, position, instruction), without the host round trips.

    Per iteration (while `loop_needs_iteration` holds for some row) and per body
    position, the rows that run there are taken `REPLAY_CHUNK` at a time, rows of one
    instruction together (of a carry op, rows that hold an object apart from those that
    do not), gathered and run by a switch on an unbatched index (`replay_examples`), so
    only that instruction's code runs, only for those rows: the cost follows the rows
    still looping, not the batch. A program that failed on some example is dead (the
    search drops it): none of its examples runs further. Rows from `real` on are padding:
    they are not run (returned as they came)."""
    ctl = states.control
    ops, args = ctl.body_ops[:, 0], ctl.body_args[:, 0]  # (B, L): a body is the same on every example
    length, pc0 = ctl.body_len[:, 0], ctl.body_pc0[:, 0]
    rows, size = ops.shape[0], min(REPLAY_CHUNK, ops.shape[0])

    def branch(op):
        def run(s, at, j, active):
            return replay_examples(cfg, op, consts, tasks[at], s, args[at, j], pc0[at] + j, active)
        return run

    branches = [branch(op) for op in range(len(OP))]  # any instruction a body may record

    padding = jnp.arange(rows) >= (rows if real is None else real)

    def alive(s, it):
        dead = jnp.any(s.control.failed, axis=1) | padding
        return loop_needs_iteration(cfg, s, it) & ~dead[:, None]

    def iterate(carry):
        it, s = carry
        active = alive(s, it)  # (B, E), fixed for this iteration
        live_rows = active.any(axis=1)

        def position(j, s):
            def run(sub, op, at, taken):
                return jax.lax.switch(op, branches, sub, at, j, active[at] & taken[:, None])

            return by_instruction(s, ops[:, j], active, live_rows & (length > j), size, run)

        steps = jnp.max(jnp.where(live_rows, length, 0))
        return it + 1, jax.lax.fori_loop(0, steps, position, s)

    return jax.lax.while_loop(lambda carry: jnp.any(alive(carry[1], carry[0])), iterate,
                              (jnp.int32(1), states))[1]


ADVANCE_CHUNK = 4  # rows of one instruction `advance_atoms` runs at a time


@functools.partial(jax.jit, static_argnums=0)
def advance_atoms(cfg: VCCConfig, consts: SceneConst, tasks: jax.Array, states: VCCState, ops: jax.Array,
                  args: jax.Array, real: jax.Array) -> VCCState:
    """Step row b of (B, E) states by its own atoms in turn (`ops[b]`, `args[b]`: K of
    them, -1 where the row's portion has no more; a subroutine is several), each step
    followed by every further iteration of the loops it closed, all in one device call
    with one switch over the instructions (so each instruction's code is compiled once,
    not once for the step and once for the replay). A row failed on some example stops
    there (the search drops it). Rows from `real` on are padding: left as they came.
    Columns past the last atom any row has cost nothing (the loop runs to that atom
    only); a single step is the one-column case."""
    rows = jnp.arange(ops.shape[0]) < real
    last = jnp.max(jnp.where(rows[:, None] & (ops >= 0), jnp.arange(ops.shape[1]) + 1, 0))

    def atom(k, s):
        run = rows & (ops[:, k] >= 0) & ~jnp.any(s.control.failed, axis=1)
        return _advance(cfg, consts, tasks, s, jnp.where(run, ops[:, k], 0), args[:, k], run)

    return jax.lax.fori_loop(0, last, atom, states)


def _advance(cfg: VCCConfig, consts: SceneConst, tasks: jax.Array, states: VCCState, ops: jax.Array,
             args: jax.Array, live: jax.Array) -> VCCState:
    """One atom of `advance_atoms` for the rows where `live` (B,); the others are left as
    they came.

    The step is iteration 0 of the replay's loop: at each position (one for the step,
    the body's for a replay) the rows that run there are taken `ADVANCE_CHUNK` at a time,
    rows of one instruction together (of a carry instruction, rows that hold an object
    apart), and run by that instruction's code only: in the step with its bookkeeping
    (`before_op`, `after_op`; a `loop_end` only closes the loop), in a replay on the
    examples still looping (as `replay_examples`). A program that failed on some
    example is dead: its loop is not replayed further."""
    size = min(ADVANCE_CHUNK, ops.shape[0])
    padding = ~live
    closed = (ops == OP["loop_end"]) & ~padding

    def branch(op):  # the instruction's own code only: the bookkeeping is op-generic, outside the switch
        def run(s, at, arg, pc, stepped):
            def per_program(fn):
                return _per_task(consts, lambda c, s, arg, pc: execute(cfg, c, s, op, arg, pc, fn), (None, 0))

            return _batched(cfg, op, per_program, tasks[at], s, arg, pc, stepped=stepped)
        return run

    branches = [branch(op) for op in range(len(OP))]
    per_example = functools.partial(jax.vmap, in_axes=(0, None))  # over a row's examples, one value per row

    def run_chunk(sub, op, at, arg, pc, active, is_step):
        """Rows `sub` (all of one instruction `op`, traced) stepped, or replayed at `pc`
        where `active`."""
        s1, step_pc = jax.vmap(per_example(lambda s, a: before_op(cfg, s, op, a)))(sub, arg)
        stepped = jnp.where(is_step, True, active & ~sub.control.failed)
        ran = jax.lax.switch(op, branches, select(is_step, s1, sub), at, arg,
                             jnp.where(is_step, step_pc, pc[:, None]), stepped)
        after = jax.vmap(jax.vmap(lambda s, s1, r: after_op(cfg, s, s1, r, op)))(sub, s1, ran)
        replayed = jax.vmap(jax.vmap(select))(active & ~sub.control.failed, ran, sub)  # per example
        return select(is_step, after, replayed)

    def alive(s, it):
        dead = jnp.any(s.control.failed, axis=1) | ~closed
        return loop_needs_iteration(cfg, s, it) & ~dead[:, None]

    def iterate(carry):
        it, s = carry
        is_step = it == 0
        active = jnp.where(is_step, ~padding[:, None], alive(s, it))  # (B, E), fixed for this iteration
        live_rows = active.any(axis=1)
        ctl = s.control  # a body is the same on every example; the step may just have closed it
        body_ops, body_args = ctl.body_ops[:, 0], ctl.body_args[:, 0]
        length, pc0 = jnp.where(is_step, 1, ctl.body_len[:, 0]), ctl.body_pc0[:, 0]

        def position(j, s):
            arg_here = jnp.where(is_step, args, body_args[:, j])

            def run(sub, op, at, taken):
                return run_chunk(sub, op, at, arg_here[at], pc0[at] + j, active[at] & taken[:, None], is_step)

            return by_instruction(s, jnp.where(is_step, ops, body_ops[:, j]), active, live_rows & (length > j),
                                  size, run)

        steps = jnp.max(jnp.where(live_rows, length, 0))
        return it + 1, jax.lax.fori_loop(0, steps, position, s)

    return jax.lax.while_loop(lambda carry: (carry[0] == 0) | jnp.any(alive(carry[1], carry[0])), iterate,
                              (jnp.int32(0), states))[1]
