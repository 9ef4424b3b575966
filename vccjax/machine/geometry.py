"""Shapes on the raster: which pixels an object or an imagined object covers.

Positions are integers in units of 1/(R*sub) of the workspace and pixel centres lie
at (j + 0.5) * sub, so a pixel's offset from an object's centre is an exact integer.
A mask therefore depends only on the shape, the width and the centre's sub-pixel
phase, and moving an object by whole pixels moves its mask exactly. Both the JAX
emulator and the reference interpreter take their masks from here.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from vccjax.machine.config import VCCConfig
from vccjax.machine.instructions import SHAPES

_STAR_INNER = math.sin(math.radians(18)) / math.sin(math.radians(54))


def star_polygon(r_out: float) -> np.ndarray:
    """The 10 vertices of a five-pointed star of outer radius r_out, first point up."""
    angles = np.radians(-90.0 + 36.0 * np.arange(10))
    radii = np.where(np.arange(10) % 2 == 0, r_out, r_out * _STAR_INNER)
    return np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)


def _inside(shape: str, dx: np.ndarray, dy: np.ndarray, w: float) -> np.ndarray:
    """Point-in-shape for offsets (dx, dy) from the centre, y downward, width w."""
    h = w / 2.0
    if shape == "square":
        return (np.abs(dx) <= h) & (np.abs(dy) <= h)
    if shape == "circle":
        return dx * dx + dy * dy <= h * h
    if shape == "diamond":
        return np.abs(dx) + np.abs(dy) <= h
    if shape == "triangle":  # apex up at -h, base at +h, base width w
        return (dy >= -h) & (dy <= h) & (np.abs(dx) <= (dy + h) / 2.0)
    if shape == "star":  # even-odd rule on the 10-vertex outline
        poly = star_polygon(h)
        inside = np.zeros(dx.shape, bool)
        for k in range(10):
            (x0, y0), (x1, y1) = poly[k], poly[(k + 1) % 10]
            crosses = (y0 > dy) != (y1 > dy)
            with np.errstate(divide="ignore", invalid="ignore"):
                xc = x0 + (dy - y0) * (x1 - x0) / (y1 - y0)
            inside ^= crosses & (dx < xc)
        return inside
    raise ValueError(f"unknown shape {shape!r}")


@functools.lru_cache(maxsize=65536)
def _relative_mask(shape: str, width_units: float, phase_x: int, phase_y: int, sub: int):
    """Mask pixels relative to the centre pixel, for a centre at sub-pixel phase (px, py)."""
    reach = int(math.ceil(width_units / (2 * sub))) + 1
    d = np.arange(-reach, reach + 1)
    dr, dc = np.meshgrid(d, d, indexing="ij")
    # pixel (q + dc) has centre (q + dc) * sub + sub/2; the object centre is q * sub + phase
    ox = (dc * sub + sub // 2 - phase_x).astype(np.float64)
    oy = (dr * sub + sub // 2 - phase_y).astype(np.float64)
    inside = _inside(shape, ox, oy, width_units)
    inside[reach, reach] = True  # the centre pixel always belongs to the object
    rows, cols = np.nonzero(inside)
    out = (rows - reach).astype(np.int32), (cols - reach).astype(np.int32)
    out[0].flags.writeable = False
    out[1].flags.writeable = False
    return out


def object_pixels(shape: int | str, width: float, cx: int, cy: int, cfg: VCCConfig):
    """(rows, cols) of the pixels an object covers; may lie outside the raster."""
    name = SHAPES[shape] if isinstance(shape, (int, np.integer)) else shape
    qx, px = divmod(int(cx), cfg.sub)
    qy, py = divmod(int(cy), cfg.sub)
    dr, dc = _relative_mask(name, float(width) * cfg.units, px, py, cfg.sub)
    return dr + qy, dc + qx


def mask_intervals(rows: np.ndarray, cols: np.ndarray, n_rows: int) -> tuple[int, np.ndarray]:
    """A mask as its top row and, per row of an n_rows window, two column runs (lo1, hi1, lo2, hi2).

    An empty run has lo > hi. Every shape here has at most two runs per row (the star's
    legs); more is an error.
    """
    top = int(rows.min())
    out = np.tile(np.array([1, 0, 1, 0], np.int32), (n_rows, 1))
    for r in range(top, int(rows.max()) + 1):
        if r - top >= n_rows:
            raise ValueError(f"mask taller than the {n_rows}-row window")
        c = np.sort(cols[rows == r])
        if c.size == 0:
            continue
        breaks = np.nonzero(np.diff(c) > 1)[0]
        if breaks.size > 1:
            raise ValueError(f"mask row {r} has {breaks.size + 1} runs; at most 2 are supported")
        if breaks.size == 0:
            out[r - top, :2] = c[0], c[-1]
        else:
            b = breaks[0]
            out[r - top] = c[0], c[b], c[b + 1], c[-1]
    return top, out


def imagined_pixels(kind: int, fx: int, fy: int, cfg: VCCConfig):
    """(rows, cols) of an imagined object's footprint at the fovea, clipped to the raster.

    circle: a disc of radius 0.25; hline: a bar of thickness 0.02 across the width.
    Tested in exact integers: |d| <= U/4  <=>  16 |d|^2 <= U^2, |dy| <= U/100 <=> 100 |dy| <= U.
    """
    u, s = cfg.units, cfg.sub
    centres = np.arange(cfg.raster, dtype=np.int64) * s + s // 2
    dy = (centres - fy)[:, None]
    dx = (centres - fx)[None, :]
    if kind == 0:
        inside = 16 * (dx * dx + dy * dy) <= u * u
    elif kind == 1:
        inside = np.broadcast_to(100 * np.abs(dy) <= u, (cfg.raster, cfg.raster))
    else:
        raise ValueError(f"unknown imagined kind {kind}")
    rows, cols = np.nonzero(inside)
    return rows.astype(np.int32), cols.astype(np.int32)


def shape_polygon(shape: str, x: float, y: float, w: float, px: float) -> np.ndarray | None:
    """A drawn shape's outline, scaled by `px` pixels per workspace unit (None for a
    circle). Images and the scene generator draw shapes from it."""
    h = w / 2
    if shape == "square":
        pts = [(-h, -h), (h, -h), (h, h), (-h, h)]
    elif shape == "diamond":
        pts = [(0, -h), (h, 0), (0, h), (-h, 0)]
    elif shape == "triangle":
        pts = [(0, -h), (h, h), (-h, h)]
    elif shape == "star":
        pts = [tuple(p) for p in star_polygon(h)]
    elif shape == "circle":
        return None
    else:
        raise ValueError(f"unknown shape {shape!r}")
    return np.array([((x + dx) * px, (y + dy) * px) for dx, dy in pts], np.float64)
