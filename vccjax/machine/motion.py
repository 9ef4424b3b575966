"""Contact and motion on the raster, the emulator's hot path.

Raster lines are uint32 bit words. An object's mask has at most two runs per row and
per column (tables made at load time), so it is cheap to test against an occupancy
bitmap of everything else:

- a move left/right/up/down is solved in closed form: per mask line, the first
  occupied pixel ahead of each run (count-leading-zeros on the bit words) gives how
  far the object can slide; up/down use the transposed (per-column) tables;
- a move toward a point samples its path (whole-pixel offsets, at most one pixel per
  axis per step) and stops before the first sample that collides or leaves the workspace.

"Leaves the workspace" means the object's w x w box leaves the unit square (the test
scene validation uses, in integer units), precomputed per object as offset bounds.

Both agree with the reference interpreter's literal pixel-set sweep (tested).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from vccjax.machine.config import VCCConfig
from vccjax.machine.state import SceneConst, VCCState

_ONE = np.uint32(1)


def low_bits(n: jax.Array) -> jax.Array:
    """uint32 with the n lowest bits set, n in [0, 32] (XLA shifts by >= 32 give 0)."""
    return jnp.left_shift(_ONE, n.astype(jnp.uint32)) - _ONE


def run_bits(lo: jax.Array, hi: jax.Array, cfg: VCCConfig) -> jax.Array:
    """Bit words (..., W) of the run [lo, hi]; empty when lo > hi."""
    start = jnp.arange(cfg.words, dtype=jnp.int32) * 32
    a = jnp.clip(lo[..., None] - start, 0, 32)
    b = jnp.clip(hi[..., None] + 1 - start, 0, 32)
    return low_bits(b) & ~low_bits(a)


def fold(op, x: jax.Array, axis: int) -> jax.Array:
    """Reduce a small static axis by `op` as a chain of elementwise ops: XLA on CPU fuses
    these into the surrounding loop, where a reduce over an inner axis of a batched
    array runs many times slower."""
    parts = [jax.lax.index_in_dim(x, j, axis, keepdims=False) for j in range(x.shape[axis])]
    out = parts[0]
    for p in parts[1:]:
        out = op(out, p)
    return out


def _lines(c: SceneConst, s: VCCState, cfg: VCCConfig, axis: int):
    """Per object: its mask lines' raster indices (N, K) and runs (N, K, 2) lo, hi, now.

    axis 0: lines are rows, runs are columns; axis 1: lines are columns, runs are rows.
    """
    table, start = (c.runs, c.corner[:, 0]) if axis == 0 else (c.cruns, c.corner[:, 1])
    table = table.astype(jnp.int32)  # stored as int16 (state.RUN_DTYPE)
    off = s.blackboard.offset
    line_off, run_off = (off[:, 1], off[:, 0]) if axis == 0 else (off[:, 0], off[:, 1])
    lines = (start + line_off)[:, None] + jnp.arange(cfg.mask_rows, dtype=jnp.int32)[None, :]
    shifted = table + run_off[:, None, None]
    return lines, shifted[..., 0::2], shifted[..., 1::2]


def occupancy(
    c: SceneConst, s: VCCState, cfg: VCCConfig, exclude, axis: int = 0, imagined: bool = True
) -> jax.Array:
    """(R, W) bit lines of every alive object except slot `exclude`, plus the imagined one.

    Objects never overlap (scenes are validated, motion and imagination keep it so), so
    adding disjoint bit words is OR-ing them. Each object's K lines are added as one block
    at its first line (a mask's pixels lie in the raster, so its first line is in [0, R)
    and lines past the raster are empty): a scatter of N blocks, not of N * K lines.
    """
    lines, lo, hi = _lines(c, s, cfg, axis)
    keep = s.blackboard.alive & (jnp.arange(cfg.n_max) != exclude)
    bits = fold(jnp.bitwise_or, run_bits(lo, hi, cfg), 2)  # (N, K, W)
    bits = jnp.where(keep[:, None, None], bits, jnp.uint32(0))
    blocks = jax.lax.ScatterDimensionNumbers(
        update_window_dims=(1, 2), inserted_window_dims=(), scatter_dims_to_operand_dims=(0,)
    )
    occ = jnp.zeros((cfg.raster + cfg.mask_rows, cfg.words), jnp.uint32)
    occ = jax.lax.scatter_add(occ, lines[:, :1], bits, blocks)[: cfg.raster]
    if imagined:
        im = imagined_runs(s.blackboard.imagined_kind, s.blackboard.imagined_position, cfg)[axis]
        occ = occ | run_bits(im[:, 0], im[:, 1], cfg)
    return occ


def contains(c: SceneConst, s: VCCState, cfg: VCCConfig, point: jax.Array) -> jax.Array:
    """(N,) whether each alive object's mask holds the pixel of `point` (position units)."""
    col = jnp.minimum(point[0] // cfg.sub, cfg.raster - 1)
    row = jnp.minimum(point[1] // cfg.sub, cfg.raster - 1)
    b = s.blackboard
    k = row - (c.corner[:, 0] + b.offset[:, 1])
    ok = (k >= 0) & (k < cfg.mask_rows) & b.alive
    runs = c.runs[jnp.arange(cfg.n_max), jnp.clip(k, 0, cfg.mask_rows - 1)].astype(jnp.int32)
    x = col - b.offset[:, 0]
    inside = ((x >= runs[:, 0]) & (x <= runs[:, 1])) | ((x >= runs[:, 2]) & (x <= runs[:, 3]))
    return ok & inside


def _isqrt(x: jax.Array) -> jax.Array:
    """floor(sqrt(x)) of int32 x in [0, 2**24): float32 root, corrected by one either way."""
    d = jnp.floor(jnp.sqrt(x.astype(jnp.float32))).astype(jnp.int32)
    d = jnp.where(d * d > x, d - 1, d)
    return jnp.where((d + 1) * (d + 1) <= x, d + 1, d)


def imagined_runs(kind: jax.Array, at: jax.Array, cfg: VCCConfig) -> tuple[jax.Array, jax.Array]:
    """Per-row and per-column runs (R, 2) of the imagined footprint (lo > hi: empty), in
    closed form: on a line at distance d from the centre, a pixel centre c is inside when
    |c - centre| <= reach(d) (circle: 16 (dx^2 + dy^2) <= U^2, so reach = isqrt((U^2 -
    16 d^2) // 16); hline: every pixel of a row within U / 100, so reach = U // 100 down a
    column). The pixels of geometry.imagined_pixels (tested). The state keeps only the kind
    and position: the runs are remade where contact needs them."""
    u, sub, r = cfg.units, cfg.sub, cfg.raster
    centres = jnp.arange(r, dtype=jnp.int32) * sub + sub // 2
    none = jnp.full(r, -1, jnp.int32)

    def disc(d):
        m = u * u - 16 * d * d
        return jnp.where(m >= 0, _isqrt(jnp.maximum(m, 0) // 16), -1)

    def around(centre, reach):  # pixels q with |q * sub + sub / 2 - centre| <= reach
        lo = jnp.maximum(-((sub // 2 + reach - centre) // sub), 0)
        hi = jnp.minimum((centre + reach - sub // 2) // sub, r - 1)
        empty = (reach < 0) | (lo > hi)
        return jnp.stack([jnp.where(empty, 1, lo), jnp.where(empty, 0, hi)], axis=1).astype(jnp.int32)

    dy, dx = centres - at[1], centres - at[0]
    row_reach = jnp.where(kind == 0, disc(dy), jnp.where(100 * jnp.abs(dy) <= u, 2 * u, -1))
    col_reach = jnp.where(kind == 0, disc(dx), jnp.full(r, u // 100, jnp.int32))
    row_reach = jnp.where(kind >= 0, row_reach, none)
    col_reach = jnp.where(kind >= 0, col_reach, none)
    return around(at[0], row_reach), around(at[1], col_reach)


def _ctz(x: jax.Array) -> jax.Array:
    """Count trailing zeros of nonzero uint32 words."""
    return 31 - jax.lax.clz(x & (~x + _ONE)).astype(jnp.int32)


def slide(c: SceneConst, s: VCCState, cfg: VCCConfig, axis: int, sign: int) -> VCCState:
    """Carry the held object straight until contact or the workspace edge (closed form).

    axis 0 moves along x (left/right), axis 1 along y (up/down); sign is +1 or -1.
    """
    i = s.hand.held
    r = cfg.raster
    occ = occupancy(c, s, cfg, exclude=i, axis=0 if axis == 0 else 1)
    lines, lo, hi = _lines(c, s, cfg, 0 if axis == 0 else 1)
    lines, lo, hi = lines[i], lo[i], hi[i]  # (K,), (K, 2), (K, 2)
    words = occ[jnp.clip(lines, 0, r - 1)][:, None, :]  # (K, 1, W)
    start = jnp.arange(cfg.words, dtype=jnp.int32) * 32
    if sign > 0:  # first occupied pixel after hi (R: none; the box bound below then decides)
        ahead = words & ~low_bits(jnp.clip(hi[..., None] + 1 - start, 0, 32))
        first = jnp.min(jnp.where(ahead != 0, start + _ctz(ahead), r), axis=-1)
        gap = first - hi - 1
    else:  # last occupied pixel before lo (-1: none)
        behind = words & low_bits(jnp.clip(lo[..., None] - start, 0, 32))
        last = jnp.max(jnp.where(behind != 0, start + 31 - jax.lax.clz(behind).astype(jnp.int32), -1), axis=-1)
        gap = lo - last - 1
    shift = jnp.min(jnp.where(lo <= hi, gap, r))
    off = s.blackboard.offset[i, axis]
    room = c.box[i, 2 * axis + 1] - off if sign > 0 else off - c.box[i, 2 * axis]
    shift = jnp.minimum(shift, room)  # the object's w x w box stays in the workspace
    return _carried(s, cfg, jnp.zeros(2, jnp.int32).at[axis].set(sign * shift))


def _carried(s: VCCState, cfg: VCCConfig, delta: jax.Array) -> VCCState:
    """The held object and the hand moved by `delta` whole pixels."""
    b, h = s.blackboard, s.hand
    return s.replace(blackboard=b.replace(offset=b.offset.at[h.held].add(delta)),
                     hand=h.replace(position=h.position + delta * cfg.sub))


def toward_path(start: jax.Array, target: jax.Array, cfg: VCCConfig) -> jax.Array:
    """(R + 1, 2) pixel offsets from `start` toward `target` (position units): the whole-pixel
    displacement rounded half up, sampled with at most one pixel per axis per step; samples
    past arrival repeat the last."""
    sub = cfg.sub
    dp = (2 * (target - start) + sub) // (2 * sub)
    n = jnp.max(jnp.abs(dp))
    t = jnp.minimum(jnp.arange(cfg.raster + 1, dtype=jnp.int32), n)[:, None]
    nn = jnp.maximum(n, 1)
    return (2 * t * dp[None, :] + nn) // (2 * nn)


def carry_toward(c: SceneConst, s: VCCState, cfg: VCCConfig, target: jax.Array) -> VCCState:
    """Carry the held object toward `target` until contact or arrival, testing every sample.

    The held object's mask is made once as bit words at its current place; at each sample
    it is shifted as a whole (words moved by d // 32, bits by d % 32) and tested against
    the K occupancy lines under it, read as one slice of the padded bitmap. The test ORs
    the words, then the lines, by `fold` (in that order): under vmap on CPU, a reduce
    there was most of the carry's time."""
    i = s.hand.held
    k, w = cfg.mask_rows, cfg.words
    off = s.blackboard.offset[i]
    path = toward_path(c.base[i] + off * cfg.sub, target, cfg)  # (P, 2)
    total = off[None, :] + path  # (P, 2) offsets since load
    box = c.box[i]
    out = (
        (total[:, 0] < box[0]) | (total[:, 0] > box[1]) | (total[:, 1] < box[2]) | (total[:, 1] > box[3])
    )
    lines, lo, hi = _lines(c, s, cfg, 0)
    mask = jnp.sum(run_bits(lo[i], hi[i], cfg), axis=1, dtype=jnp.uint32)  # (K, W): the two runs are disjoint
    wide = jnp.pad(mask, ((0, 0), (w + 1, w + 1)))
    occ = jnp.pad(occupancy(c, s, cfg, exclude=i), ((k, k), (0, 0)))  # rows past the raster: empty

    def hits(d):  # d: whole-pixel shift from here; a sample outside the box is `out` anyway
        q, b = d[0] // 32, (d[0] % 32).astype(jnp.uint32)
        here = jax.lax.dynamic_slice(wide, (0, w + 1 - q), (k, w))
        below = jax.lax.dynamic_slice(wide, (0, w - q), (k, w))
        moved = jnp.left_shift(here, b) | jnp.right_shift(below, jnp.uint32(32) - b)  # >> 32 is 0
        under = jax.lax.dynamic_slice(occ, (lines[i, 0] + d[1] + k, 0), (k, w))
        return fold(jnp.bitwise_or, fold(jnp.bitwise_or, moved & under, 1), 0) != 0

    bad = out | jax.vmap(hits)(path)
    first_bad = jnp.where(bad.any(), jnp.argmax(bad), path.shape[0])
    return _carried(s, cfg, path[jnp.maximum(first_bad - 1, 0)])
