"""Carrying on the reference machine: the literal pixel-set sweep (docs/vcc.md, Motion).

The held object moves by whole pixels along a path of offsets and stops before the
first one where its mask would overlap another alive object or the imagined object, or
its w x w box would leave the workspace; the hand moves by the same displacement. The
JAX emulator finds the same stop in closed form (`motion.py`); the tests hold them equal.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from vccjax.machine.config import VCCConfig
from vccjax.machine.geometry import imagined_pixels
from vccjax.machine.scene import box_inside, to_units

if TYPE_CHECKING:
    from vccjax.machine.reference import RefMachine

Path = list[tuple[int, int]]  # whole-pixel offsets from where the object is, (0, 0) first


def toward(start: tuple[int, int], target: tuple[int, int], cfg: VCCConfig) -> Path:
    """The displacement in whole pixels, rounded half up, sampled rounded half up along it
    (at most one pixel per axis per sample)."""
    s = cfg.sub
    dpx = (2 * (target[0] - start[0]) + s) // (2 * s)
    dpy = (2 * (target[1] - start[1]) + s) // (2 * s)
    n = max(abs(dpx), abs(dpy))
    return [(0, 0)] + [((2 * t * dpx + n) // (2 * n), (2 * t * dpy + n) // (2 * n)) for t in range(1, n + 1)]


def straight(ux: int, uy: int, cfg: VCCConfig) -> Path:
    """One pixel per sample in direction (ux, uy), across the whole raster."""
    return [(t * ux, t * uy) for t in range(cfg.raster + 1)]


def carry(m: RefMachine, i: int, path: Path) -> None:
    """Move object i (the held one) and the hand along `path` to its last sample before
    the first that collides or leaves the workspace."""
    cfg, b = m.cfg, m.blackboard
    s = cfg.sub
    x, y = m.centre(i)
    w = to_units(m.widths[i], cfg)
    # the other objects' and the imagined pixels on a raster with a wide margin (masks
    # may reach past the workspace); the object moves by whole pixels, so its mask at
    # offset (dx, dy) is its mask now shifted by (dy, dx) rows and columns
    margin = 2 * cfg.raster
    blocked = np.zeros((5 * cfg.raster,) * 2, bool)
    if b.imagined_kind >= 0:
        rows, cols = imagined_pixels(b.imagined_kind, *b.imagined_position, cfg)
        blocked[rows + margin, cols + margin] = True
    for j in m.real_alive():
        if j != i:
            rows, cols = m.object_pixels(j)
            blocked[rows + margin, cols + margin] = True
    rows, cols = m.object_pixels(i)
    steps = np.asarray(path[1:], np.int64).reshape(-1, 2)
    hits = blocked[rows[None, :] + margin + steps[:, 1:], cols[None, :] + margin + steps[:, :1]].any(axis=1)
    last = (0, 0)
    for (dx, dy), hit in zip(steps.tolist(), hits.tolist()):
        if hit or not box_inside(x + dx * s, y + dy * s, w, cfg):
            break
        last = (dx, dy)
    ox, oy = b.offset[i]
    b.offset[i] = (ox + last[0], oy + last[1])
    hx, hy = m.hand.position
    m.hand.position = (hx + last[0] * s, hy + last[1] * s)
