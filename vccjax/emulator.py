"""The VCC in JAX: pure, jit-able instruction semantics over `VCCState`.

- `step(cfg, c, s, op, arg)`: one program instruction, op traced (dispatch by
  `lax.switch`; under `vmap` with a batched op every branch runs, so batch by op).
- `step_batch(cfg, op, consts, states, args)`: many states, one static op: only that
  op's code runs. This is what the search uses.
- `run_program` / `run_batch`: a whole (padded) program on one scene or a batch.

Each op returns (new state, failed?); `_commit` keeps the old state on failure and
records the failing program index. The reference interpreter (`reference.py`) is the
oracle for all of it.
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np

from vccjax import motion
from vccjax.config import DEFAULT_CONFIG, VCCConfig
from vccjax.instructions import FORBIDDEN_IN_LOOP, N_OPS, NAMES, OP
from vccjax.program import Program
from vccjax.state import SceneConst, VCCState, centres, init_state

_FORBIDDEN = np.array([OP[n] for n in sorted(FORBIDDEN_IN_LOOP)], np.int32)
_NONE = jnp.int32(-1)


# ---- attention ----------------------------------------------------------------------
def refresh(cfg: VCCConfig, c: SceneConst, s: VCCState) -> VCCState:
    """If A is stale: alive objects passing the filters, by distance from the fovea, ties by slot."""
    d = centres(c, s, cfg) - s.fovea[None, :]
    d2 = jnp.sum(d * d, axis=1)
    ok = (
        s.alive
        & ((s.shape_filter < 0) | (c.shape == s.shape_filter))
        & ((s.color_filter < 0) | (s.color == s.color_filter))
    )
    n = cfg.n_max
    slot = jnp.arange(n)
    # rank by (d2, slot) among the objects that pass; a dense N x N comparison beats a sort here
    before = (d2[None, :] < d2[:, None]) | ((d2[None, :] == d2[:, None]) & (slot[None, :] < slot[:, None]))
    rank = jnp.sum(before & ok[None, :], axis=1)
    count = jnp.sum(ok)
    placed = ok[None, :] & (rank[None, :] == slot[:, None])  # (position, slot)
    attn = jnp.where(slot < count, jnp.sum(jnp.where(placed, slot[None, :], 0), axis=1), -1)
    return s.replace(
        attn=jnp.where(s.stale, attn, s.attn),
        attn_len=jnp.where(s.stale, count, s.attn_len),
        stale=jnp.bool_(False),
    )


def _unattend(s: VCCState) -> VCCState:
    return s.replace(stale=jnp.bool_(True), cursor=jnp.int32(0), attended=_NONE)


def _fixate_on(cfg: VCCConfig, s: VCCState, p: jax.Array):
    full = s.hist_len >= cfg.hist_max
    idx = jnp.minimum(s.hist_len, cfg.hist_max - 1)
    return s.replace(hist=s.hist.at[idx].set(p), hist_len=s.hist_len + 1, hist_idx=s.hist_len, fovea=p), full


def _attended_centre(cfg, c, s):
    return centres(c, s, cfg)[jnp.maximum(s.attended, 0)]


# ---- instructions (spec section 3, in the order of its table) -------------------------
def op_scene_parse(cfg, c, s, arg):
    n = cfg.n_max
    return s.replace(
        parsed=jnp.bool_(True), alive=jnp.arange(n) < c.n, color=c.color,
        offset=jnp.zeros((n, 2), jnp.int32),
    ), s.parsed


def op_set_shape_attn(cfg, c, s, arg):
    return _unattend(s.replace(shape_filter=arg)), s.shape_filter >= 0


def op_set_color_attn(cfg, c, s, arg):
    return _unattend(s.replace(color_filter=arg)), s.color_filter >= 0


def op_reset_attn(cfg, c, s, arg):
    return _unattend(s.replace(shape_filter=_NONE, color_filter=_NONE)), jnp.bool_(False)


def op_top_down_attend(cfg, c, s, arg):
    s = refresh(cfg, c, s)
    fail = s.cursor >= s.attn_len
    return s.replace(attended=s.attn[jnp.clip(s.cursor, 0, cfg.n_max - 1)]), fail


def op_next_object(cfg, c, s, arg):
    s = refresh(cfg, c, s)
    k = s.cursor + 1
    return s.replace(cursor=k, attended=_NONE), k > s.attn_len


def op_attend_pointer(cfg, c, s, arg):
    under = motion.contains(c, s, cfg, c.pointer)
    return s.replace(attended=jnp.argmax(under).astype(jnp.int32)), ~c.has_pointer | ~under.any()


def op_fixate(cfg, c, s, arg):
    u, h = cfg.units, cfg.units // 2
    targets = jnp.array([[0, h], [u, h], [h, 0], [h, u], [h, h]], jnp.int32)
    return _fixate_on(cfg, s, targets[arg])


def op_fixate_attended_object(cfg, c, s, arg):
    s2, full = _fixate_on(cfg, s, _attended_centre(cfg, c, s))
    return s2, full | (s.attended < 0)


def op_fixate_pointer(cfg, c, s, arg):
    s2, full = _fixate_on(cfg, s, c.pointer)
    return s2, full | ~c.has_pointer


def op_fixate_previous(cfg, c, s, arg):
    h = s.hist_idx - 1
    return s.replace(hist_idx=h, fovea=s.hist[jnp.maximum(h, 0)]), s.hist_idx == 0


def op_fixate_next(cfg, c, s, arg):
    h = s.hist_idx + 1
    return s.replace(hist_idx=h, fovea=s.hist[jnp.minimum(h, cfg.hist_max - 1)]), h >= s.hist_len


def _hand_to_attended(cfg, c, s, arg, carry: bool = True):
    target = _attended_centre(cfg, c, s)
    holding = s.held >= 0
    fail = (s.attended < 0) | (holding & (s.attended == s.held))
    if not carry:  # nobody in the batch holds anything: skip the carry's cost
        return s.replace(hand=target), fail
    carried = motion.carry_toward(c, s, cfg, target)
    return _select(holding, carried, s.replace(hand=target)), fail


def op_move_hand_to_attended_object(cfg, c, s, arg):
    return _hand_to_attended(cfg, c, s, arg)


def op_grab_object(cfg, c, s, arg):
    under = motion.contains(c, s, cfg, s.hand)
    return s.replace(held=jnp.argmax(under).astype(jnp.int32)), (s.held >= 0) | ~under.any()


def op_release_object(cfg, c, s, arg):
    return s.replace(held=_NONE), s.held < 0


def _move_direction(axis, sign):
    def op(cfg, c, s, arg):
        return motion.slide(c, s, cfg, axis, sign), s.held < 0
    return op


op_move_hand_left = _move_direction(0, -1)
op_move_hand_right = _move_direction(0, 1)
op_move_hand_up = _move_direction(1, -1)
op_move_hand_down = _move_direction(1, 1)


def op_move_hand_to_pointer(cfg, c, s, arg):
    return motion.carry_toward(c, s, cfg, c.pointer), (s.held < 0) | ~c.has_pointer


def op_move_hand_to_fixate_collision(cfg, c, s, arg):
    return motion.carry_toward(c, s, cfg, s.fovea), s.held < 0


def op_fill_color(cfg, c, s, arg):
    return s.replace(color=s.color.at[s.attended].set(arg)), s.attended < 0


def op_remove_from_imagine_buffer(cfg, c, s, arg):
    a = s.attended
    s2 = s.replace(
        alive=s.alive.at[a].set(False), held=jnp.where(s.held == a, _NONE, s.held),
        attended=_NONE, stale=jnp.bool_(True),
    )
    return s2, a < 0


def op_imagine_object(cfg, c, s, arg):
    runs, _ = motion.imagined_runs(arg, s.fovea, cfg)
    occ = motion.occupancy(c, s, cfg, exclude=_NONE, imagined=False)
    overlap = jnp.any(occ & motion.run_bits(runs[:, 0], runs[:, 1], cfg))
    s2 = s.replace(imag_kind=jnp.int32(arg), imag_pos=s.fovea)
    return s2, (s.imag_kind >= 0) | overlap


def op_reset_imagination(cfg, c, s, arg):
    return s.replace(imag_kind=_NONE), s.imag_kind < 0


def op_loop_start(cfg, c, s, arg):
    s = refresh(cfg, c, s)
    return s.replace(
        in_loop=jnp.bool_(True), loop_active=s.cursor < s.attn_len,
        body_len=jnp.int32(0), body_pc0=s.pc,
    ), jnp.bool_(False)


def op_loop_end(cfg, c, s, arg):
    """Checks and closes the loop; the remaining iterations are replayed by `_replay`."""
    recorded = jnp.where(jnp.arange(cfg.body_max) < s.body_len, s.body_ops, -1)
    complete = jnp.any(recorded == OP["top_down_attend"]) & jnp.any(recorded == OP["next_object"])
    return s.replace(in_loop=jnp.bool_(False)), ~s.in_loop | ~complete


def _replay(cfg: VCCConfig, c: SceneConst, s: VCCState, active) -> VCCState:
    """Replay the stored body while k < len(A), up to n_max iterations in all (the first ran
    eagerly). Kept out of the op dispatch so that only states at a loop_end pay for it."""

    def done(carry):
        st, it, j = carry
        return st.failed | ((j == 0) & ((it >= cfg.n_max) | (st.cursor >= st.attn_len)))

    def body(carry):
        st, it, j = carry
        st = _execute_switch(cfg, c, st, st.body_ops[j], st.body_args[j], st.body_pc0 + j, _BODY_BRANCHES)
        j = j + 1
        wrap = j >= st.body_len
        return st, it + wrap, jnp.where(wrap, 0, j)

    start = jnp.where(active & s.loop_active & ~s.failed, 1, cfg.n_max)
    s, _, _ = jax.lax.while_loop(lambda cr: ~done(cr), body, (s, jnp.int32(start), jnp.int32(0)))
    return s


OPS = tuple(globals()["op_" + name] for name in NAMES)


# ---- committing, dispatch, loop bookkeeping -------------------------------------------
def _select(pred, a, b):
    return jax.tree.map(lambda x, y: jnp.where(pred, x, y), a, b)


def _commit(old: VCCState, new: VCCState, fail, pc) -> VCCState:
    out = _select(fail, old, new)
    return out.replace(failed=out.failed | fail, fail_index=jnp.where(fail, pc, out.fail_index))


def _execute(cfg: VCCConfig, op: int, c: SceneConst, s: VCCState, arg, pc, fn=None) -> VCCState:
    """One instruction's semantics (static op), without loop bookkeeping; `fn` may stand
    in for the op's function (a cheaper variant valid for the batch at hand)."""
    new, fail = (fn or OPS[op])(cfg, c, s, jnp.asarray(arg, jnp.int32))
    if op != OP["scene_parse"]:
        fail = fail | ~s.parsed
    return _commit(s, new, fail, pc)


def _branches(loops: bool):
    def make(op):
        if not loops and NAMES[op] in ("loop_start", "loop_end"):
            return lambda cfg, c, s, arg, pc: s  # never recorded in a loop body
        return functools.partial(_execute, op=op)

    return [make(op) for op in range(N_OPS)] + [lambda cfg, c, s, arg, pc: s]  # last: padding


def _call(branch, cfg, c, s, arg, pc):
    return branch(cfg=cfg, c=c, s=s, arg=arg, pc=pc)


_TOP_BRANCHES = _branches(loops=True)
_BODY_BRANCHES = _branches(loops=False)


def _execute_switch(cfg, c, s, op, arg, pc, branches) -> VCCState:
    idx = jnp.where(op < 0, N_OPS, op)
    fns = [functools.partial(_call, b, cfg) for b in branches]
    return jax.lax.switch(idx, fns, c, s, arg, pc)


def _step(cfg: VCCConfig, c: SceneConst, s: VCCState, op, arg, execute, replay: bool = True) -> VCCState:
    """Loop bookkeeping of spec section 5 around one instruction; `op` static or traced.
    replay=False leaves a closed loop's remaining iterations to the caller (`replay_examples`)."""
    may_end_loop = (not isinstance(op, int) or op == OP["loop_end"]) and replay
    op = jnp.asarray(op, jnp.int32)
    pc = s.pc
    recording = s.in_loop & (op != OP["loop_end"])
    bad = recording & (jnp.any(op == _FORBIDDEN) | (s.body_len >= cfg.body_max))
    slot = jnp.minimum(s.body_len, cfg.body_max - 1)
    s1 = s.replace(
        pc=pc + 1,
        body_ops=jnp.where(recording, s.body_ops.at[slot].set(op), s.body_ops),
        body_args=jnp.where(recording, s.body_args.at[slot].set(arg), s.body_args),
        body_len=s.body_len + recording,
    )
    ran = execute(c, s1, arg, pc)
    if may_end_loop:
        ran = _replay(cfg, c, ran, (op == OP["loop_end"]) & ~recording)
    skipped = recording & ~s.loop_active  # a zero-iteration loop only records its body
    out = _select(skipped, s1, ran)
    out = _select(bad, _commit(s1, s1, True, pc), out)
    return _select(s.failed | (op < 0), s, out)


def step(cfg: VCCConfig, c: SceneConst, s: VCCState, op, arg) -> VCCState:
    """One program instruction with a traced op (-1 is padding: no effect)."""
    return _step(cfg, c, s, op, arg,
                 lambda c_, s_, a_, pc_: _execute_switch(cfg, c_, s_, op, a_, pc_, _TOP_BRANCHES))


def step_op(cfg: VCCConfig, op: int, c: SceneConst, s: VCCState, arg, fn=None, replay: bool = True) -> VCCState:
    """One program instruction with a static op: only that op's code is traced."""
    return _step(cfg, c, s, op, arg,
                 lambda c_, s_, a_, pc_: _execute(cfg, op, c_, s_, a_, pc_, fn), replay)


@functools.partial(jax.jit, static_argnums=(0, 1))
def step_batch(cfg: VCCConfig, op: int, consts: SceneConst, states: VCCState, args: jax.Array) -> VCCState:
    """Step a batch of states (each with its own scene) by the same instruction."""
    return _batched(cfg, op, lambda fn: jax.vmap(functools.partial(step_op, cfg, op, fn=fn)),
                    consts, states, args)


def _fails_empty_handed(cfg, c, s, arg):
    return s, jnp.bool_(True)


# Carrying is the costly part of a hand move, and it only happens with an object held:
# when no state in a batch holds one, these ops run a stand-in with the same outcome.
EMPTY_HANDED = {
    OP["move_hand_to_attended_object"]: functools.partial(_hand_to_attended, carry=False),
    **{OP[f"move_hand_{d}"]: _fails_empty_handed for d in ("left", "right", "up", "down")},
    OP["move_hand_to_pointer"]: _fails_empty_handed,
    OP["move_hand_to_fixate_collision"]: _fails_empty_handed,
}


def _batched(cfg: VCCConfig, op: int, make, first, states, *rest):
    """`make(fn)` builds the batched step `(first, states, *rest) -> states` with `fn`
    standing in for the op's function; a carry op pays for the carry only when some
    state in the batch holds an object."""
    if op not in EMPTY_HANDED:
        return make(None)(first, states, *rest)
    return jax.lax.cond(jnp.any(states.held >= 0), make(None), make(EMPTY_HANDED[op]), first, states, *rest)


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
    with `loop_needs_iteration` and `replay_examples` (one static op at a time, instead
    of every instruction's code in a traced loop)."""

    def per_program(fn):
        one = functools.partial(step_op, cfg, op, fn=fn, replay=replay)
        return _per_task(consts, one, (None,))

    return _batched(cfg, op, per_program, tasks, states, args)


def loop_needs_iteration(cfg: VCCConfig, s: VCCState, iteration) -> jax.Array:
    """Whether a just-closed loop runs another iteration (`iteration` = iterations done;
    spec section 5: while k < len(A), at most n_max in all, the first ran eagerly)."""
    return s.loop_active & ~s.failed & (iteration < cfg.n_max) & (s.cursor < s.attn_len)


@functools.partial(jax.jit, static_argnums=(0, 1))
def replay_examples(cfg: VCCConfig, op: int, consts: SceneConst, tasks: jax.Array, states: VCCState,
                    args: jax.Array, pcs: jax.Array, active: jax.Array) -> VCCState:
    """One body instruction of a replayed loop, static op, for states where `active`
    (B, E); the others are returned unchanged. consts, tasks as in `step_examples`;
    args, pcs: (B,)."""

    def per_program(fn):
        def one(c, s, arg, pc, act):
            return _select(act & ~s.failed, _execute(cfg, op, c, s, arg, pc, fn), s)

        return _per_task(consts, one, (None, None, 0))

    return _batched(cfg, op, per_program, tasks, states, args, pcs, active)


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
