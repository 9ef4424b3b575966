"""Running the JAX machine: dispatch, failure, loops (docs/vcc.md sections 4 and 5).

- `step(cfg, c, s, op, arg)`: one program instruction, op traced (dispatch by
  `lax.switch`; under `vmap` with a batched op every branch runs, so batch by op).
- `step_op(cfg, c, s, op, arg)`: the same with a static op: only that op's code is traced.
- `step_batch(cfg, consts, states, op, args)`: many states (each with its own scene),
  one static op.
- `run_program` / `run_batch` / `run_programs`: a whole (padded) program.

`_commit` keeps the old state on failure and records the failing program index.
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.instructions import FORBIDDEN_IN_LOOP, N_OPS, NAMES, OP
from vccjax.machine.ops import OPS, select
from vccjax.machine.program import Program
from vccjax.machine.state import SceneConst, VCCState, init_state

_FORBIDDEN = np.array([OP[n] for n in sorted(FORBIDDEN_IN_LOOP)], np.int32)

# ---- committing, dispatch, loop bookkeeping -------------------------------------------
def _commit(old: VCCState, new: VCCState, fail, pc) -> VCCState:
    out = select(fail, old, new)
    ctl = out.control
    return out.replace(control=ctl.replace(failed=ctl.failed | fail, fail_index=jnp.where(fail, pc, ctl.fail_index)))


def execute(cfg: VCCConfig, c: SceneConst, s: VCCState, op: int, arg, pc, fn=None) -> VCCState:
    """One instruction's semantics (static op), without loop bookkeeping; `fn` may stand
    in for the op's function (a cheaper variant valid for the batch at hand)."""
    new, fail = (fn or OPS[op])(cfg, c, s, jnp.asarray(arg, jnp.int32))
    if op != OP["scene_parse"]:
        fail = fail | ~s.blackboard.parsed
    return _commit(s, new, fail, pc)


def _branches(loops: bool):
    def make(op):
        if not loops and NAMES[op] in ("loop_start", "loop_end"):
            return lambda cfg, c, s, arg, pc: s  # never recorded in a loop body
        return functools.partial(execute, op=op)

    return [make(op) for op in range(N_OPS)] + [lambda cfg, c, s, arg, pc: s]  # last: padding


def _call(branch, cfg, c, s, arg, pc):
    return branch(cfg=cfg, c=c, s=s, arg=arg, pc=pc)


_TOP_BRANCHES = _branches(loops=True)
_BODY_BRANCHES = _branches(loops=False)


def _execute_switch(cfg, c, s, op, arg, pc, branches) -> VCCState:
    idx = jnp.where(op < 0, N_OPS, op)
    fns = [functools.partial(_call, b, cfg) for b in branches]
    return jax.lax.switch(idx, fns, c, s, arg, pc)


def _replay(cfg: VCCConfig, c: SceneConst, s: VCCState, active) -> VCCState:
    """Replay the stored body while k < len(A), up to n_max iterations in all (the first ran
    eagerly). Kept out of the op dispatch so that only states at a loop_end pay for it."""

    def done(carry):
        st, it, j = carry
        a = st.attention
        return st.control.failed | ((j == 0) & ((it >= cfg.n_max) | (a.cursor >= a.attended_list_len)))

    def body(carry):
        st, it, j = carry
        ctl = st.control
        st = _execute_switch(cfg, c, st, ctl.body_ops[j], ctl.body_args[j], ctl.body_pc0 + j, _BODY_BRANCHES)
        j = j + 1
        wrap = j >= ctl.body_len
        return st, it + wrap, jnp.where(wrap, 0, j)

    start = jnp.where(active & s.control.loop_active & ~s.control.failed, 1, cfg.n_max)
    s, _, _ = jax.lax.while_loop(lambda cr: ~done(cr), body, (s, jnp.int32(start), jnp.int32(0)))
    return s


def before_op(cfg: VCCConfig, s: VCCState, op, arg) -> tuple[VCCState, jax.Array]:
    """The bookkeeping before a program instruction runs (docs/vcc.md section 5): the
    program counter advanced and, in an open loop, the instruction recorded in the body.
    Returns that state and the instruction's program index."""
    op = jnp.asarray(op, jnp.int32)
    ctl = s.control
    recording = ctl.in_loop & (op != OP["loop_end"])
    slot = jnp.minimum(ctl.body_len, cfg.body_max - 1)
    return s.replace(control=ctl.replace(
        pc=ctl.pc + 1,
        body_ops=jnp.where(recording, ctl.body_ops.at[slot].set(op), ctl.body_ops),
        body_args=jnp.where(recording, ctl.body_args.at[slot].set(arg), ctl.body_args),
        body_len=ctl.body_len + recording,
    )), ctl.pc


def after_op(cfg: VCCConfig, s: VCCState, s1: VCCState, ran: VCCState, op) -> VCCState:
    """What a program instruction leaves, given the state `s` before it, `s1` from
    `before_op` and `ran`, the instruction run on `s1`: a forbidden or overlong body
    instruction fails, one in a zero-iteration loop is only recorded, and a state that
    had failed (or padding, op -1) stays as it was."""
    op = jnp.asarray(op, jnp.int32)
    ctl = s.control
    recording = ctl.in_loop & (op != OP["loop_end"])
    bad = recording & (jnp.any(op == _FORBIDDEN) | (ctl.body_len >= cfg.body_max))
    skipped = recording & ~ctl.loop_active  # a zero-iteration loop only records its body
    out = select(skipped, s1, ran)
    out = select(bad, _commit(s1, s1, True, ctl.pc), out)
    return select(ctl.failed | (op < 0), s, out)


def _step(cfg: VCCConfig, c: SceneConst, s: VCCState, op, arg, run_op, replay: bool = True) -> VCCState:
    """Loop bookkeeping (docs/vcc.md section 5) around one instruction; `op` static or traced.
    replay=False leaves a closed loop's remaining iterations to the caller (the search
    replays them one static instruction at a time)."""
    may_end_loop = (not isinstance(op, int) or op == OP["loop_end"]) and replay
    s1, pc = before_op(cfg, s, op, arg)
    ran = run_op(c, s1, arg, pc)
    if may_end_loop:
        recording = s.control.in_loop & (jnp.asarray(op, jnp.int32) != OP["loop_end"])
        ran = _replay(cfg, c, ran, (jnp.asarray(op, jnp.int32) == OP["loop_end"]) & ~recording)
    return after_op(cfg, s, s1, ran, op)


def step(cfg: VCCConfig, c: SceneConst, s: VCCState, op, arg) -> VCCState:
    """One program instruction with a traced op (-1 is padding: no effect)."""
    return _step(cfg, c, s, op, arg,
                 lambda c_, s_, a_, pc_: _execute_switch(cfg, c_, s_, op, a_, pc_, _TOP_BRANCHES))


def step_op(cfg: VCCConfig, c: SceneConst, s: VCCState, op: int, arg, fn=None, replay: bool = True) -> VCCState:
    """One program instruction with a static op: only that op's code is traced. `fn` may
    stand in for the op's function (a cheaper variant valid for the batch at hand)."""
    return _step(cfg, c, s, op, arg,
                 lambda c_, s_, a_, pc_: execute(cfg, c_, s_, op, a_, pc_, fn), replay)


@functools.partial(jax.jit, static_argnums=(0, 3))
def step_batch(cfg: VCCConfig, consts: SceneConst, states: VCCState, op: int, args: jax.Array) -> VCCState:
    """Step a batch of states (each with its own scene) by the same static instruction."""
    return jax.vmap(lambda c, s, a: step_op(cfg, c, s, op, a))(consts, states, args)


def _run(cfg, c, ops, args):
    return jax.lax.fori_loop(
        0, ops.shape[0], lambda i, s: step(cfg, c, s, ops[i], args[i]), init_state(cfg)
    )


@functools.partial(jax.jit, static_argnums=0)
def run_program(cfg: VCCConfig, c: SceneConst, ops: jax.Array, args: jax.Array) -> VCCState:
    """Run a padded program (op -1 = padding) on one scene from the initial state."""
    return _run(cfg, c, ops, args)


@functools.partial(jax.jit, static_argnums=0)
def run_batch(cfg: VCCConfig, consts: SceneConst, ops: jax.Array, args: jax.Array) -> VCCState:
    """One program on a batch of scenes; the program is shared, so each step runs one branch."""
    return jax.vmap(_run, in_axes=(None, 0, None, None))(cfg, consts, ops, args)


@functools.partial(jax.jit, static_argnums=0)
def run_programs(cfg: VCCConfig, consts: SceneConst, ops: jax.Array, args: jax.Array) -> VCCState:
    """Different programs (B, L) on their own scenes (B, ...); every switch branch runs."""
    return jax.vmap(_run, in_axes=(None, 0, 0, 0))(cfg, consts, ops, args)


def pad_length(n: int) -> int:
    """Padded program length: the next multiple of 16, so that few shapes are compiled."""
    return max(16, -(-n // 16) * 16)


def run(program: Program, c: SceneConst, cfg: VCCConfig = DEFAULT_CONFIG) -> VCCState:
    """Convenience: run a Program on one loaded scene."""
    ops, args, _ = program.arrays(pad_length(len(program)))
    return run_program(cfg, c, jnp.asarray(ops), jnp.asarray(args))
