"""What the argument predictor sees of an example pair (paper, "Argument prediction").

Per example a (21, 15, 15) array on the machine's 15x15 grid (an object is at the cell
of its centre, `floor(position * 14)` as `vccjax.machine.state.grid15`):
- channels 0-9, the input: 5 shapes, 4 colours, the pointer (binary);
- channels 10-19, output minus input in the same encoding (-1, 0, 1);
- channel 20, 1 where any of channels 10-19 is non-zero (something changed there).

Scenes are first flattened to small integer arrays (`scene_cells`) so that many
examples are featurised at once with one scatter (`features_from_cells`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from vccjax.machine.instructions import COLORS, SHAPES
from vccjax.machine.scene import Scene

GRID = 15
CHANNELS = 21
INPUT_CHANNELS = len(SHAPES) + len(COLORS) + 1  # 10
POINTER_CHANNEL = INPUT_CHANNELS - 1
MAX_OBJECTS = 8  # the most objects any generated scene holds (test split: 2-8)
CHANNEL_NAMES: tuple[str, ...] = (
    tuple(f"in:{s}" for s in SHAPES) + tuple(f"in:{c}" for c in COLORS) + ("in:pointer",)
    + tuple(f"diff:{s}" for s in SHAPES) + tuple(f"diff:{c}" for c in COLORS) + ("diff:pointer", "changed")
)


def cell(v: float) -> int:
    """The 15x15 grid cell of a unit-square coordinate."""
    return min(GRID - 1, max(0, int(np.floor(v * (GRID - 1)))))


def scene_cells(scene: Scene) -> np.ndarray:
    """(MAX_OBJECTS + 1, 4) int8: per object (shape, colour, row, column), -1 rows where
    there is none; the last row is the pointer (-1, -1, row, column), or all -1."""
    if len(scene.objects) > MAX_OBJECTS:
        raise ValueError(f"a scene of {len(scene.objects)} objects; the predictor reads at most {MAX_OBJECTS}")
    out = np.full((MAX_OBJECTS + 1, 4), -1, np.int8)
    for i, o in enumerate(scene.objects):
        out[i] = (SHAPES.index(o.shape), COLORS.index(o.color), cell(o.y), cell(o.x))
    if scene.pointer is not None:
        out[MAX_OBJECTS, 2:] = (cell(scene.pointer[1]), cell(scene.pointer[0]))
    return out


def _grids(cells: np.ndarray) -> np.ndarray:
    """(..., MAX_OBJECTS + 1, 4) cells -> (..., 10, 15, 15) binary input channels."""
    lead = cells.shape[:-2]
    flat = cells.reshape(-1, MAX_OBJECTS + 1, 4).astype(np.int64)
    g = np.zeros((len(flat), INPUT_CHANNELS, GRID, GRID), np.int8)
    b = np.arange(len(flat))[:, None]
    objs = flat[:, :MAX_OBJECTS]
    present = objs[..., 0] >= 0
    bb, rr, cc = np.broadcast_to(b, present.shape)[present], objs[..., 2][present], objs[..., 3][present]
    g[bb, objs[..., 0][present], rr, cc] = 1
    g[bb, len(SHAPES) + objs[..., 1][present], rr, cc] = 1
    ptr = flat[:, MAX_OBJECTS]
    has = ptr[:, 2] >= 0
    g[np.nonzero(has)[0], POINTER_CHANNEL, ptr[has, 2], ptr[has, 3]] = 1
    return g.reshape(lead + (INPUT_CHANNELS, GRID, GRID))


def features_from_cells(inputs: np.ndarray, outputs: np.ndarray) -> np.ndarray:
    """(..., 9, 4) input and output cells -> (..., 21, 15, 15) int8 features."""
    a, b = _grids(inputs), _grids(outputs)
    diff = b - a
    changed = (np.abs(diff).sum(axis=-3, keepdims=True) >= 1).astype(np.int8)
    return np.concatenate([a, diff, changed], axis=-3)


def pair_features(pairs: Sequence[tuple[Scene, Scene]]) -> np.ndarray:
    """(E, 21, 15, 15) int8 features of a concept's example pairs."""
    if not pairs:
        raise ValueError("no example pairs to featurise")
    ins = np.stack([scene_cells(a) for a, _ in pairs])
    outs = np.stack([scene_cells(b) for _, b in pairs])
    return features_from_cells(ins, outs)
