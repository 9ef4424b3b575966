"""What the per-family instruction tests share: units, slot read-outs of the reference
machine, and the scenes several families use (docs/vcc.md section 3)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from tests.helpers import obj, run_both, scene

from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.geometry import imagined_pixels, object_pixels
from vccjax.machine.instructions import COLORS, FIXATE_TARGETS, IMAGINE_KINDS, NAMES, SHAPES, arg_domain
from vccjax.machine.scene import to_units

CFG = DEFAULT_CONFIG
U = CFG.units  # 1024 position units across
C = U // 2  # the centre, 512
R = CFG.raster  # 64 pixels
SUB = CFG.sub  # 16 units per pixel
PIXEL = 1 / R  # one pixel, in workspace coordinates
CENTRE = (C, C)



# ---- helpers ----------------------------------------------------------------------------
def u(v: float) -> int:
    """A workspace coordinate in integer units, as scene_parse rounds it."""
    return to_units(v, CFG)


def shape_id(name: str) -> int:
    return SHAPES.index(name)


def color_id(name: str) -> int:
    return COLORS.index(name)


def centre_of(m, i: int) -> tuple[int, int]:
    return m.centre(i)


def slot(m, i: int) -> SimpleNamespace:
    """Object slot i as the reference's blackboard holds it (centre in units)."""
    x, y = m.centre(i)
    b = m.blackboard
    return SimpleNamespace(shape=m.shapes[i], color=b.color[i], x=x, y=y, width=m.widths[i], alive=b.alive[i])


def colors(m) -> list[int]:
    """The scene's objects' colours on the blackboard."""
    return m.blackboard.color[: len(m.scene.objects)]


def imagined(m) -> tuple[int, int, int] | None:
    """(kind, x, y) of the imagined object, or None."""
    b = m.blackboard
    return None if b.imagined_kind < 0 else (b.imagined_kind, *b.imagined_position)


def mask(m, i: int, dx: int = 0, dy: int = 0) -> set[tuple[int, int]]:
    """(row, col) pixels of object i, shifted by (dx, dy) whole pixels, from geometry directly."""
    o = slot(m, i)
    rows, cols = object_pixels(SHAPES[o.shape], o.width, o.x + dx * SUB, o.y + dy * SUB, CFG)
    return set(zip(rows.tolist(), cols.tolist()))


def obstacles(m, i: int) -> set[tuple[int, int]]:
    """Pixels of every alive object except i, plus the imagined object's footprint."""
    out: set[tuple[int, int]] = set()
    for j in m.real_alive():
        if j != i:
            out |= mask(m, j)
    if imagined(m) is not None:
        rows, cols = imagined_pixels(*imagined(m), CFG)
        out |= set(zip(rows.tolist(), cols.tolist()))
    return out


def assert_no_overlap(m) -> None:
    """The output scene has no overlapping masks (and lies inside the workspace)."""
    m.output_scene().validate(CFG)
    held = m.hand.held
    if held >= 0:
        assert not (mask(m, held) & obstacles(m, held))


def assert_in_contact(m, i: int, steps: list[tuple[int, int]]) -> None:
    """Object i is stopped at contact: it overlaps nothing now, and one more pixel step in
    (one of) the given direction(s) would overlap another object or the imagined one."""
    blocked = obstacles(m, i)
    assert not (mask(m, i) & blocked), "the moved object overlaps something"
    assert any(mask(m, i, dx, dy) & blocked for dx, dy in steps), "the moved object is not in contact"


def box_gap(m, i, direction):
    """Distance from object i's w x w box to the workspace border on one side (>= 0)."""
    o = slot(m, i)
    x, y, h = o.x / U, o.y / U, o.width / 2
    gap = {"left": x - h, "right": 1 - x - h, "up": y - h, "down": 1 - y - h}[direction]
    assert gap >= 0
    return gap


def mask_extent(m, i: int) -> tuple[int, int, int, int]:
    rows, cols = zip(*mask(m, i))
    return min(rows), max(rows), min(cols), max(cols)


def alive_ids(m) -> list[int]:
    return m.real_alive()


def with_arg(name: str) -> str:
    dom = arg_domain(name)
    return f"{name}({dom[0]})" if dom else name


# ---- shared scenes ----------------------------------------------------------------------
# slot 1 nearest the centre, then slot 2, then slot 0
THREE = scene(
    obj("square", "red", 0.1, 0.1),
    obj("circle", "green", 0.6, 0.5),
    obj("diamond", "blue", 0.5, 0.8),
)

# two squares and two circles, two red and two blue; distances from the centre all differ
FILTER_SCENE = scene(
    obj("square", "red", 0.2, 0.2),  # 0: dist .424
    obj("square", "blue", 0.75, 0.25),  # 1: dist .354
    obj("circle", "red", 0.25, 0.72),  # 2: dist .333
    obj("circle", "blue", 0.6, 0.55),  # 3: dist .112
)

# one square at the exact centre (under the hand at start)
CENTRED = scene(obj("square", "red", 0.5, 0.5))


