"""The instructions' semantics in JAX (docs/vcc.md section 3, grouped by the memory each acts on, in the order of its table).

Each `op_<name>(cfg, c, s, arg)` is pure and returns (new state, failed?); `step.py`
keeps the old state when an op fails and records where. The scalar reference
(`reference.py`) states the same rules for one machine, and is the oracle for these.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from vccjax.machine import motion
from vccjax.machine.config import VCCConfig
from vccjax.machine.instructions import NAMES, OP
from vccjax.machine.state import SceneConst, VCCState, centres


def select(pred, a, b):
    """Pick, leaf by leaf, `a` where `pred` holds and `b` elsewhere (states or scenes)."""
    return jax.tree.map(lambda x, y: jnp.where(pred, x, y), a, b)


def none() -> jax.Array:
    """-1 as int32, the 'nothing' of a slot register (built when traced, not at import)."""
    return jnp.int32(-1)


# ---- attention ----------------------------------------------------------------------
def refresh(cfg: VCCConfig, c: SceneConst, s: VCCState) -> VCCState:
    """If A is stale: alive objects passing the filters, by distance from the fovea, ties by slot."""
    a, b = s.attention, s.blackboard
    d = centres(c, b, cfg) - s.fovea.position[None, :]
    d2 = jnp.sum(d * d, axis=1)
    ok = (
        b.alive
        & ((a.shape_filter < 0) | (c.shape == a.shape_filter))
        & ((a.color_filter < 0) | (b.color == a.color_filter))
    )
    n = cfg.n_max
    slot = jnp.arange(n)
    # rank by (d2, slot) among the objects that pass; a dense N x N comparison beats a sort here
    before = (d2[None, :] < d2[:, None]) | ((d2[None, :] == d2[:, None]) & (slot[None, :] < slot[:, None]))
    rank = jnp.sum(before & ok[None, :], axis=1)
    count = jnp.sum(ok)
    placed = ok[None, :] & (rank[None, :] == slot[:, None])  # (position, slot)
    listed = jnp.where(slot < count, jnp.sum(jnp.where(placed, slot[None, :], 0), axis=1), -1)
    return s.replace(attention=a.replace(
        attended_list=jnp.where(a.stale, listed, a.attended_list),
        attended_list_len=jnp.where(a.stale, count, a.attended_list_len),
        stale=jnp.bool_(False),
    ))


def _unattend(s: VCCState, **filters) -> VCCState:
    """Filters set (if given), A stale, k = 0, nothing attended."""
    return s.replace(attention=s.attention.replace(
        **filters, stale=jnp.bool_(True), cursor=jnp.int32(0), attended=none()))


def _attend(s: VCCState, **fields) -> VCCState:
    return s.replace(attention=s.attention.replace(**fields))


def _fixate_on(cfg: VCCConfig, s: VCCState, p: jax.Array):
    f = s.fovea
    full = f.history_len >= cfg.hist_max
    idx = jnp.minimum(f.history_len, cfg.hist_max - 1)
    f = f.replace(history=f.history.at[idx].set(p), history_len=f.history_len + 1,
                  history_index=f.history_len, position=p)
    return s.replace(fovea=f), full


def _attended_centre(cfg, c, s):
    return centres(c, s.blackboard, cfg)[jnp.maximum(s.attention.attended, 0)]


def _hand(s: VCCState, **fields) -> VCCState:
    return s.replace(hand=s.hand.replace(**fields))


# ---- instructions (docs/vcc.md section 3, grouped by the memory each acts on, in the order of its table) -------------------------
def op_scene_parse(cfg, c, s, arg):
    n, b = cfg.n_max, s.blackboard
    return s.replace(blackboard=b.replace(
        parsed=jnp.bool_(True), alive=jnp.arange(n) < c.n, color=c.color,
        offset=jnp.zeros((n, 2), jnp.int32),
    )), b.parsed


def op_set_shape_attn(cfg, c, s, arg):
    return _unattend(s, shape_filter=arg), s.attention.shape_filter >= 0


def op_set_color_attn(cfg, c, s, arg):
    return _unattend(s, color_filter=arg), s.attention.color_filter >= 0


def op_reset_attn(cfg, c, s, arg):
    return _unattend(s, shape_filter=none(), color_filter=none()), jnp.bool_(False)


def op_top_down_attend(cfg, c, s, arg):
    s = refresh(cfg, c, s)
    a = s.attention
    fail = a.cursor >= a.attended_list_len
    return _attend(s, attended=a.attended_list[jnp.clip(a.cursor, 0, cfg.n_max - 1)]), fail


def op_next_object(cfg, c, s, arg):
    s = refresh(cfg, c, s)
    k = s.attention.cursor + 1
    return _attend(s, cursor=k, attended=none()), k > s.attention.attended_list_len


def op_attend_pointer(cfg, c, s, arg):
    under = motion.contains(c, s, cfg, c.pointer)
    return _attend(s, attended=jnp.argmax(under).astype(jnp.int32)), ~c.has_pointer | ~under.any()


def op_fixate(cfg, c, s, arg):
    u, h = cfg.units, cfg.units // 2
    targets = jnp.array([[0, h], [u, h], [h, 0], [h, u], [h, h]], jnp.int32)
    return _fixate_on(cfg, s, targets[arg])


def op_fixate_attended_object(cfg, c, s, arg):
    s2, full = _fixate_on(cfg, s, _attended_centre(cfg, c, s))
    return s2, full | (s.attention.attended < 0)


def op_fixate_pointer(cfg, c, s, arg):
    s2, full = _fixate_on(cfg, s, c.pointer)
    return s2, full | ~c.has_pointer


def op_fixate_previous(cfg, c, s, arg):
    f = s.fovea
    h = f.history_index - 1
    return s.replace(fovea=f.replace(history_index=h, position=f.history[jnp.maximum(h, 0)])), f.history_index == 0


def op_fixate_next(cfg, c, s, arg):
    f = s.fovea
    h = f.history_index + 1
    at = f.history[jnp.minimum(h, cfg.hist_max - 1)]
    return s.replace(fovea=f.replace(history_index=h, position=at)), h >= f.history_len


def hand_to_attended(cfg, c, s, arg, carry: bool = True):
    target = _attended_centre(cfg, c, s)
    attended, held = s.attention.attended, s.hand.held
    holding = held >= 0
    fail = (attended < 0) | (holding & (attended == held))
    if not carry:  # nobody in the batch holds anything: skip the carry's cost
        return _hand(s, position=target), fail
    carried = motion.carry_toward(c, s, cfg, target)
    return select(holding, carried, _hand(s, position=target)), fail


def op_move_hand_to_attended_object(cfg, c, s, arg):
    return hand_to_attended(cfg, c, s, arg)


def op_grab_object(cfg, c, s, arg):
    under = motion.contains(c, s, cfg, s.hand.position)
    return _hand(s, held=jnp.argmax(under).astype(jnp.int32)), (s.hand.held >= 0) | ~under.any()


def op_release_object(cfg, c, s, arg):
    return _hand(s, held=none()), s.hand.held < 0


def _move_direction(axis, sign):
    def op(cfg, c, s, arg):
        return motion.slide(c, s, cfg, axis, sign), s.hand.held < 0
    return op


op_move_hand_left = _move_direction(0, -1)
op_move_hand_right = _move_direction(0, 1)
op_move_hand_up = _move_direction(1, -1)
op_move_hand_down = _move_direction(1, 1)


def op_move_hand_to_pointer(cfg, c, s, arg):
    return motion.carry_toward(c, s, cfg, c.pointer), (s.hand.held < 0) | ~c.has_pointer


def op_move_hand_to_fixate_collision(cfg, c, s, arg):
    return motion.carry_toward(c, s, cfg, s.fovea.position), s.hand.held < 0


def op_fill_color(cfg, c, s, arg):
    b, a = s.blackboard, s.attention.attended
    return s.replace(blackboard=b.replace(color=b.color.at[a].set(arg))), a < 0


def op_remove_from_imagine_buffer(cfg, c, s, arg):
    b, a, held = s.blackboard, s.attention.attended, s.hand.held
    s2 = s.replace(blackboard=b.replace(alive=b.alive.at[a].set(False)))
    s2 = _hand(s2, held=jnp.where(held == a, none(), held))
    return _attend(s2, attended=none(), stale=jnp.bool_(True)), a < 0


def op_imagine_object(cfg, c, s, arg):
    b, at = s.blackboard, s.fovea.position
    runs, _ = motion.imagined_runs(arg, at, cfg)
    occ = motion.occupancy(c, s, cfg, exclude=none(), imagined=False)
    overlap = jnp.any(occ & motion.run_bits(runs[:, 0], runs[:, 1], cfg))
    s2 = s.replace(blackboard=b.replace(imagined_kind=jnp.int32(arg), imagined_position=at))
    return s2, (b.imagined_kind >= 0) | overlap


def op_reset_imagination(cfg, c, s, arg):
    b = s.blackboard
    return s.replace(blackboard=b.replace(imagined_kind=none())), b.imagined_kind < 0


def op_loop_start(cfg, c, s, arg):
    s = refresh(cfg, c, s)
    a, ctl = s.attention, s.control
    return s.replace(control=ctl.replace(
        in_loop=jnp.bool_(True), loop_active=a.cursor < a.attended_list_len,
        body_len=jnp.int32(0), body_pc0=ctl.pc,
    )), jnp.bool_(False)


def op_loop_end(cfg, c, s, arg):
    """Checks and closes the loop; the remaining iterations are replayed by `_replay`."""
    ctl = s.control
    recorded = jnp.where(jnp.arange(cfg.body_max) < ctl.body_len, ctl.body_ops, -1)
    complete = jnp.any(recorded == OP["top_down_attend"]) & jnp.any(recorded == OP["next_object"])
    return s.replace(control=ctl.replace(in_loop=jnp.bool_(False))), ~ctl.in_loop | ~complete


OPS = tuple(globals()["op_" + name] for name in NAMES)
