"""The instructions' semantics in JAX (docs/vcc.md section 3, in the order of its table).

Each `op_<name>(cfg, c, s, arg)` is pure and returns (new state, failed?); `step.py`
keeps the old state when an op fails and records where. The scalar reference
(`reference.py`) states the same rules for one machine, and is the oracle for these.
"""

from __future__ import annotations

import functools

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
    return s.replace(stale=jnp.bool_(True), cursor=jnp.int32(0), attended=none())


def _fixate_on(cfg: VCCConfig, s: VCCState, p: jax.Array):
    full = s.hist_len >= cfg.hist_max
    idx = jnp.minimum(s.hist_len, cfg.hist_max - 1)
    return s.replace(hist=s.hist.at[idx].set(p), hist_len=s.hist_len + 1, hist_idx=s.hist_len, fovea=p), full


def _attended_centre(cfg, c, s):
    return centres(c, s, cfg)[jnp.maximum(s.attended, 0)]


# ---- instructions (docs/vcc.md section 3, in the order of its table) -------------------------
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
    return _unattend(s.replace(shape_filter=none(), color_filter=none())), jnp.bool_(False)


def op_top_down_attend(cfg, c, s, arg):
    s = refresh(cfg, c, s)
    fail = s.cursor >= s.attn_len
    return s.replace(attended=s.attn[jnp.clip(s.cursor, 0, cfg.n_max - 1)]), fail


def op_next_object(cfg, c, s, arg):
    s = refresh(cfg, c, s)
    k = s.cursor + 1
    return s.replace(cursor=k, attended=none()), k > s.attn_len


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


def hand_to_attended(cfg, c, s, arg, carry: bool = True):
    target = _attended_centre(cfg, c, s)
    holding = s.held >= 0
    fail = (s.attended < 0) | (holding & (s.attended == s.held))
    if not carry:  # nobody in the batch holds anything: skip the carry's cost
        return s.replace(hand=target), fail
    carried = motion.carry_toward(c, s, cfg, target)
    return select(holding, carried, s.replace(hand=target)), fail


def op_move_hand_to_attended_object(cfg, c, s, arg):
    return hand_to_attended(cfg, c, s, arg)


def op_grab_object(cfg, c, s, arg):
    under = motion.contains(c, s, cfg, s.hand)
    return s.replace(held=jnp.argmax(under).astype(jnp.int32)), (s.held >= 0) | ~under.any()


def op_release_object(cfg, c, s, arg):
    return s.replace(held=none()), s.held < 0


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
        alive=s.alive.at[a].set(False), held=jnp.where(s.held == a, none(), s.held),
        attended=none(), stale=jnp.bool_(True),
    )
    return s2, a < 0


def op_imagine_object(cfg, c, s, arg):
    runs, _ = motion.imagined_runs(arg, s.fovea, cfg)
    occ = motion.occupancy(c, s, cfg, exclude=none(), imagined=False)
    overlap = jnp.any(occ & motion.run_bits(runs[:, 0], runs[:, 1], cfg))
    s2 = s.replace(imag_kind=jnp.int32(arg), imag_pos=s.fovea)
    return s2, (s.imag_kind >= 0) | overlap


def op_reset_imagination(cfg, c, s, arg):
    return s.replace(imag_kind=none()), s.imag_kind < 0


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


OPS = tuple(globals()["op_" + name] for name in NAMES)
