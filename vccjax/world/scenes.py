"""Seeded random scenes (valid by construction) for tests, demos and benchmarks.

The tabletop-world dataset builds on this with per-concept rules.
"""

from __future__ import annotations

import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.errors import SceneError
from vccjax.machine.geometry import object_pixels, shape_polygon
from vccjax.machine.instructions import COLORS, SHAPES
from vccjax.machine.scene import Scene, SceneObject, box_inside, to_units


_FINE = 8  # subdivisions per raster pixel when finding what a drawn shape covers


def drawn_cover(shape: str, width: float, x: float, y: float, cfg: VCCConfig = DEFAULT_CONFIG):
    """(rows, cols) of the raster pixels that the drawn shape touches: a superset of the
    machine's mask, whose pixels are those with their *centre* inside. A star's thin tips
    cross pixels whose centres lie outside it, so masks alone under-state how close two
    drawn shapes come."""
    import cv2  # only scene generation rasterises drawn outlines; the machine never does

    r = cfg.raster
    reach = int(np.ceil(width / 2 * r)) + 2
    qx, qy = int(x * r), int(y * r)
    if shape == "circle":  # exact: a pixel is touched if its nearest point is within the radius
        ii = np.arange(qy - reach, qy + reach + 1)
        jj = np.arange(qx - reach, qx + reach + 1)
        dy = np.clip(y * r, ii, ii + 1) - y * r
        dx = np.clip(x * r, jj, jj + 1) - x * r
        rows, cols = np.nonzero(dy[:, None] ** 2 + dx[None, :] ** 2 <= (width / 2 * r) ** 2)
        return rows + qy - reach, cols + qx - reach
    # polygons: the pixels the outline passes through (sampled every 1/32 pixel) and the
    # interior (filled at _FINE x the raster; any touched sub-pixel counts)
    n = (2 * reach + 1) * _FINE
    fine = np.zeros((n, n), np.uint8)
    ox, oy = (qx - reach) / r, (qy - reach) / r  # the window's corner, in workspace units
    poly = shape_polygon(shape, x - ox, y - oy, width, r * _FINE) - 0.5
    cv2.fillPoly(fine, [np.round(poly * 16).astype(np.int32)], 1, cv2.LINE_8, 4)
    touched = fine.reshape(2 * reach + 1, _FINE, 2 * reach + 1, _FINE).max(axis=(1, 3))
    corners = shape_polygon(shape, x, y, width, r)
    step = np.roll(corners, -1, axis=0) - corners
    t = np.linspace(0.0, 1.0, int(np.ceil(np.abs(step).max() * 32)) + 2)[:, None, None]
    pix = np.floor(corners + t * step).astype(int).reshape(-1, 2)
    touched[pix[:, 1] - qy + reach, pix[:, 0] - qx + reach] = 1
    rows, cols = np.nonzero(touched)
    return rows + qy - reach, cols + qx - reach

def _grow(mask: np.ndarray, g: int) -> np.ndarray:
    """A boolean mask dilated by a (2g+1) x (2g+1) square: every pixel within g in both
    directions of a set pixel (a binary max filter; outside the raster counts as empty)."""
    p = np.pad(mask, g)
    rows = np.zeros((p.shape[0], mask.shape[1]), bool)
    for d in range(2 * g + 1):
        rows |= p[:, d : d + mask.shape[1]]
    out = np.zeros(mask.shape, bool)
    for d in range(2 * g + 1):
        out |= rows[d : d + mask.shape[0]]
    return out


def random_scene(
    rng: np.random.Generator,
    n_objects: int | tuple[int, int] = (2, 6),
    *,
    widths: tuple[float, float] = (0.05, 0.15),
    pointer: bool = False,
    cfg: VCCConfig = DEFAULT_CONFIG,
    max_tries: int = 200,
    gap: int = 2,
    pointer_clearance: int = 3,
    shapes: tuple[str, ...] = SHAPES,
    colors: tuple[str, ...] = COLORS,
    pointer_on_object: bool = False,
) -> Scene:
    """A valid scene: objects drawn uniformly, placed by rejection.

    Generated inputs keep `gap` raster pixels between the pixels objects' drawn shapes
    touch (`drawn_cover`, a superset of their masks), so that drawn shapes never touch,
    as in the paper's figures, and an image parser can tell them apart; the pointer
    stays `pointer_clearance` pixels away from every object, unless `pointer_on_object`:
    then it lies on a pixel of a random object's mask (what `attend_pointer` reads).
    Shapes and colours are drawn uniformly from `shapes` and `colors` (default: all).
    """
    if isinstance(n_objects, tuple):
        n = int(rng.integers(n_objects[0], n_objects[1] + 1))
    else:
        n = int(n_objects)
    if n > cfg.n_max:
        raise SceneError(f"asked for {n} objects; n_max is {cfg.n_max}")
    r = cfg.raster
    covered = np.zeros((r, r), bool)  # objects' masks
    blocked = np.zeros((r, r), bool)  # masks grown by `gap`
    objs: list[SceneObject] = []
    for _ in range(n):
        for _ in range(max_tries):
            w = float(rng.uniform(*widths))
            x, y = (float(v) for v in rng.uniform(w / 2, 1 - w / 2, size=2))
            cand = SceneObject(str(rng.choice(shapes)), str(rng.choice(colors)), x, y, w)
            if not box_inside(to_units(x, cfg), to_units(y, cfg), to_units(w, cfg), cfg):
                continue
            rows, cols = object_pixels(cand.shape, w, to_units(x, cfg), to_units(y, cfg), cfg)
            if blocked[rows, cols].any():
                continue
            rows, cols = drawn_cover(cand.shape, w, x, y, cfg)
            keep = (rows >= 0) & (rows < r) & (cols >= 0) & (cols < r)
            rows, cols = rows[keep], cols[keep]
            if blocked[rows, cols].any():
                continue
            objs.append(cand)
            covered[rows, cols] = True
            mask = np.zeros((r, r), np.uint8)
            mask[rows, cols] = 1
            blocked |= _grow(mask > 0, gap)
            break
        else:
            raise SceneError(f"could not place object {len(objs)} in {max_tries} tries")
    ptr = None
    if pointer and pointer_on_object and objs:
        o = objs[int(rng.integers(len(objs)))]
        rows, cols = object_pixels(o.shape, o.width, to_units(o.x, cfg), to_units(o.y, cfg), cfg)
        k = int(rng.integers(len(rows)))
        return Scene(tuple(objs), ((cols[k] + 0.5) / r, (rows[k] + 0.5) / r))  # the pixel's centre
    if pointer:
        c = pointer_clearance
        for _ in range(max_tries):
            px, py = (float(v) for v in rng.uniform(0.05, 0.95, size=2))
            i, j = min(int(py * r), r - 1), min(int(px * r), r - 1)
            if not covered[max(i - c, 0) : i + c + 1, max(j - c, 0) : j + c + 1].any():
                ptr = (px, py)
                break
        else:
            raise SceneError(f"could not place the pointer clear of objects in {max_tries} tries")
    return Scene(tuple(objs), ptr)
