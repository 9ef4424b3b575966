"""The machine's working memories as fixed-shape arrays (flax.struct pytrees).

`SceneConst` holds what a scene fixes (shapes, widths, masks at load time, the
pointer) and is shared by every program prefix run on that scene; `VCCState` holds
what instructions change, as the five memories of `memories.py` (the reference's have
the same names). Object masks are not stored: an object's mask is its load-time mask
(two column runs per row) shifted by its whole-pixel offset.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
from flax import struct

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.geometry import mask_intervals, object_pixels
from vccjax.machine.instructions import COLORS, SHAPES
from vccjax.machine.memories import padded
from vccjax.machine.scene import Scene, SceneObject, to_units


# Mask runs are raster indices (< 512, or the empty run 1, 0): int16 halves what the
# search's batched steps read when they gather a concept's scenes per program; widened
# to int32 where they are used.
RUN_DTYPE = np.int16


@struct.dataclass
class SceneConst:
    n: jax.Array  # () number of objects
    shape: jax.Array  # (N,) shape index
    color: jax.Array  # (N,) initial color index
    width: jax.Array  # (N,) float32 width (unit square)
    base: jax.Array  # (N, 2) centre at load, position units (x, y)
    runs: jax.Array  # (N, K, 4) int16 column runs (lo1, hi1, lo2, hi2) per mask row, from row corner[0]
    cruns: jax.Array  # (N, K, 4) int16 row runs per mask column, from column corner[1]
    corner: jax.Array  # (N, 2) the mask's top row and left column at load
    box: jax.Array  # (N, 4) pixel offsets keeping the w x w box in the workspace: x min/max, y min/max
    has_pointer: jax.Array  # () bool
    pointer: jax.Array  # (2,) position units


@struct.dataclass
class Blackboard:
    parsed: jax.Array  # () bool
    alive: jax.Array  # (N,) bool
    color: jax.Array  # (N,)
    offset: jax.Array  # (N, 2) whole-pixel displacement since load (x, y)
    imagined_kind: jax.Array  # () -1 none, 0 circle, 1 hline
    imagined_position: jax.Array  # (2,)


@struct.dataclass
class Fovea:
    position: jax.Array  # (2,)
    history: jax.Array = padded("history_len")  # (H, 2) fixations
    history_len: jax.Array  # ()
    history_index: jax.Array  # () h


@struct.dataclass
class Attention:
    shape_filter: jax.Array  # () -1 unset
    color_filter: jax.Array  # () -1 unset
    attended_list: jax.Array = padded("attended_list_len")  # (N,) A, slots (-1 padded)
    attended_list_len: jax.Array  # ()
    stale: jax.Array  # () bool
    cursor: jax.Array  # () k
    attended: jax.Array  # () slot or -1


@struct.dataclass
class Hand:
    position: jax.Array  # (2,)
    held: jax.Array  # () slot or -1


@struct.dataclass
class Control:
    failed: jax.Array  # () bool
    fail_index: jax.Array  # () program index of the failing instruction, -1 if none
    pc: jax.Array  # () index of the next program instruction
    in_loop: jax.Array  # () bool
    loop_active: jax.Array  # () bool: the loop runs at least one iteration
    body_ops: jax.Array = padded("body_len")  # (B,)
    body_args: jax.Array = padded("body_len")  # (B,)
    body_len: jax.Array  # ()
    body_pc0: jax.Array  # () program index of the body's first instruction


@struct.dataclass
class VCCState:
    """What instructions change, as the five memories of `memories.py` (same names as the
    reference's); the blackboard first, so that a packed row begins with it."""

    blackboard: Blackboard
    fovea: Fovea
    attention: Attention
    hand: Hand
    control: Control


def load_scene(scene: Scene, cfg: VCCConfig = DEFAULT_CONFIG, validate: bool = True) -> SceneConst:
    """A scene as arrays for the emulator (host side: the shapes are rasterised here, once)."""
    if validate:
        scene.validate(cfg)
    n, k = cfg.n_max, cfg.mask_rows
    shape = np.zeros(n, np.int32)
    color = np.zeros(n, np.int32)
    width = np.zeros(n, np.float32)
    base = np.zeros((n, 2), np.int32)
    runs = np.tile(np.array([1, 0, 1, 0], np.int32), (n, k, 1))
    cruns = runs.copy()
    corner = np.zeros((n, 2), np.int32)
    box = np.zeros((n, 4), np.int32)
    for i, o in enumerate(scene.objects):
        shape[i] = SHAPES.index(o.shape)
        color[i] = COLORS.index(o.color)
        width[i] = o.width
        base[i] = to_units(o.x, cfg), to_units(o.y, cfg)
        rows, cols = object_pixels(o.shape, o.width, int(base[i, 0]), int(base[i, 1]), cfg)
        _, runs[i] = mask_intervals(rows, cols, k)
        _, cruns[i] = mask_intervals(cols, rows, k)
        corner[i] = rows.min(), cols.min()
        box[i] = offset_bounds(int(base[i, 0]), int(base[i, 1]), to_units(o.width, cfg), cfg)
    has_ptr = scene.pointer is not None
    ptr = (to_units(scene.pointer[0], cfg), to_units(scene.pointer[1], cfg)) if has_ptr else (0, 0)
    return SceneConst(
        n=jnp.int32(len(scene.objects)), shape=jnp.asarray(shape), color=jnp.asarray(color),
        width=jnp.asarray(width), base=jnp.asarray(base),
        runs=jnp.asarray(runs, RUN_DTYPE), cruns=jnp.asarray(cruns, RUN_DTYPE), corner=jnp.asarray(corner),
        box=jnp.asarray(box), has_pointer=jnp.bool_(has_ptr),
        pointer=jnp.asarray(ptr, jnp.int32),
    )


def offset_bounds(x: int, y: int, w: int, cfg: VCCConfig) -> tuple[int, int, int, int]:
    """Whole-pixel offsets (x min, x max, y min, y max) that keep the box inside, exactly
    the offsets d with scene.box_inside(x + d * sub, ...) true."""
    s2, u2 = 2 * cfg.sub, 2 * cfg.units
    lo = lambda v: -((2 * v - w) // s2)  # noqa: E731  ceil((w - 2v) / 2sub)
    hi = lambda v: (u2 - w - 2 * v) // s2  # noqa: E731
    return lo(x), hi(x), lo(y), hi(y)


def init_state(cfg: VCCConfig = DEFAULT_CONFIG) -> VCCState:
    """The machine before `scene_parse`: empty blackboard, fovea and hand at the centre."""
    n, c = cfg.n_max, cfg.units // 2
    centre = jnp.array([c, c], jnp.int32)
    i32, no = jnp.int32, jnp.bool_(False)
    return VCCState(
        blackboard=Blackboard(
            parsed=no, alive=jnp.zeros(n, bool), color=jnp.zeros(n, i32), offset=jnp.zeros((n, 2), i32),
            imagined_kind=i32(-1), imagined_position=jnp.zeros(2, i32)),
        fovea=Fovea(
            position=centre, history=jnp.zeros((cfg.hist_max, 2), i32).at[0].set(centre),
            history_len=i32(1), history_index=i32(0)),
        attention=Attention(
            shape_filter=i32(-1), color_filter=i32(-1), attended_list=jnp.full(n, -1, i32),
            attended_list_len=i32(0), stale=jnp.bool_(True), cursor=i32(0), attended=i32(-1)),
        hand=Hand(position=centre, held=i32(-1)),
        control=Control(
            failed=no, fail_index=i32(-1), pc=i32(0), in_loop=no, loop_active=no,
            body_ops=jnp.full(cfg.body_max, -1, i32), body_args=jnp.zeros(cfg.body_max, i32),
            body_len=i32(0), body_pc0=i32(0)),
    )


def stack(trees):
    """Stack a list of pytrees (scenes or states) along a new leading batch axis."""
    return jax.tree.map(lambda *xs: jnp.stack(xs), *trees)


def centres(c: SceneConst, b: Blackboard, cfg: VCCConfig) -> jax.Array:
    """(N, 2) current object centres in position units."""
    return c.base + b.offset * cfg.sub


def output_scene(c: SceneConst, s: VCCState, cfg: VCCConfig, pointer=None) -> Scene:
    """The blackboard's real, alive objects as a Scene (host side, one unbatched state)."""
    b = s.blackboard
    cen = np.asarray(centres(c, b, cfg))
    alive, shape, color, width = (np.asarray(a) for a in (b.alive, c.shape, b.color, c.width))
    objs = tuple(
        SceneObject(SHAPES[shape[i]], COLORS[color[i]], float(cen[i, 0]) / cfg.units,
                    float(cen[i, 1]) / cfg.units, float(width[i]))
        for i in range(cfg.n_max) if alive[i]
    )
    return Scene(objs, pointer)


def object_masks(c: SceneConst, s: VCCState, cfg: VCCConfig) -> jax.Array:
    """(N, R, R) bool masks of the objects on the full raster (dead slots empty)."""
    r, b = jnp.arange(cfg.raster), s.blackboard
    k = r[None, :] - (c.corner[:, 0] + b.offset[:, 1])[:, None]  # (N, R) mask row per raster row
    valid = (k >= 0) & (k < cfg.mask_rows) & b.alive[:, None]
    runs = jnp.take_along_axis(c.runs.astype(jnp.int32), jnp.clip(k, 0, cfg.mask_rows - 1)[:, :, None], axis=1)
    runs = runs + b.offset[:, None, None, 0]
    col = r[None, None, :]
    inside = ((col >= runs[..., 0:1]) & (col <= runs[..., 1:2])) | (
        (col >= runs[..., 2:3]) & (col <= runs[..., 3:4])
    )
    return inside & valid[:, :, None]


def grid15(c: SceneConst, s: VCCState, cfg: VCCConfig) -> jax.Array:
    """(N, 2) cells of the 15x15 grid (cell = floor(position * 14)) of the object centres."""
    return (centres(c, s.blackboard, cfg) * 14) // cfg.units
