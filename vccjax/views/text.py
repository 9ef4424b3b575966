"""Scenes as text for the terminal: a character picture and a legend."""

from __future__ import annotations

import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.geometry import object_pixels
from vccjax.machine.scene import Scene, to_units

_SHAPE_CHAR = {"square": "#", "circle": "o", "diamond": "<>", "triangle": "^", "star": "*"}


def ascii_scene(scene: Scene, cfg: VCCConfig = DEFAULT_CONFIG, size: int = 32) -> list[str]:
    """A scene drawn in characters: each object by its index, the pointer as '+'."""
    grid = np.full((size, size), ".", dtype="<U1")
    f = cfg.raster // size
    for i, o in enumerate(scene.objects):
        rows, cols = object_pixels(o.shape, o.width, to_units(o.x, cfg), to_units(o.y, cfg), cfg)
        ok = (rows >= 0) & (rows < cfg.raster) & (cols >= 0) & (cols < cfg.raster)
        grid[rows[ok] // f, cols[ok] // f] = str(i % 10)
    if scene.pointer is not None:
        px, py = (min(int(v * size), size - 1) for v in scene.pointer)
        grid[py, px] = "+"
    return ["".join(r) for r in grid]


def legend(scene: Scene) -> list[str]:
    """One line per object: index, colour, shape, centre, width."""
    return [f"{i}: {o.color:6s} {o.shape:8s} ({o.x:.3f}, {o.y:.3f}) w {o.width:.3f}"
            for i, o in enumerate(scene.objects)]
