"""Where the VCC's workspace lies on the robot's table, and the physical objects that
stand for its shapes.

The VCC's workspace is the unit square, x to the right and y down as in its images.
On the table it is a square of side `WORKSPACE_SIDE` metres in front of the arm: image
up is away from the arm (+x in the world), image right is the arm's right (-y).
"""

from __future__ import annotations

import dataclasses

import numpy as np

WORKSPACE_SIDE = 0.40  # metres of table per workspace unit
WORKSPACE_CENTRE = (0.45, 0.0)  # world (x, y) of the workspace's centre
TABLE_TOP = 0.0  # the table's surface is the world's z = 0
TABLE_HALF = (0.65, 0.55)  # half extents of the table top (x, y), centred at TABLE_CENTRE
TABLE_CENTRE = (0.40, 0.0)


def to_table(u: np.ndarray | float, v: np.ndarray | float) -> np.ndarray:
    """Workspace (u right, v down, in [0, 1]) to world (x, y) on the table."""
    u, v = np.asarray(u, float), np.asarray(v, float)
    return np.stack([WORKSPACE_CENTRE[0] + (0.5 - v) * WORKSPACE_SIDE,
                     WORKSPACE_CENTRE[1] + (0.5 - u) * WORKSPACE_SIDE], -1)


def to_workspace(x: np.ndarray | float, y: np.ndarray | float) -> np.ndarray:
    """World (x, y) on the table to workspace (u, v); the inverse of `to_table`."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    return np.stack([0.5 - (y - WORKSPACE_CENTRE[1]) / WORKSPACE_SIDE,
                     0.5 - (x - WORKSPACE_CENTRE[0]) / WORKSPACE_SIDE], -1)


def on_table(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return (np.abs(np.asarray(x) - TABLE_CENTRE[0]) <= TABLE_HALF[0]) & (
        np.abs(np.asarray(y) - TABLE_CENTRE[1]) <= TABLE_HALF[1])


@dataclasses.dataclass(frozen=True)
class Body:
    """One physical object slot of the scene: its kind fixes its collision geometry
    (one compiled model serves every scenario; a scenario chooses which slots are on
    the table, where, in which colour, and how a box is turned)."""

    name: str
    kind: str  # "box", "ball", "lemon", "triangle" or "star" (a plate of that shape with a knob)
    size: float  # metres across (box: side; ball: diameter; lemon: length; plates: bounding width)
    height: float  # metres (a plate: its thickness, the knob not counted)

    @property
    def shapes(self) -> tuple[str, ...]:
        """The VCC shapes this body can be seen as from above."""
        return {"box": ("square", "diamond"), "triangle": ("triangle",), "star": ("star",)}.get(self.kind, ("circle",))

    @property
    def knob(self) -> bool:
        """A plate with a square knob in its middle: a triangle or a star has no two parallel
        faces to grip, and a triangular prism gripped at a corner tipped out of the fingers."""
        return self.kind in ("triangle", "star")

    @property
    def top(self) -> float:
        """Metres from its bottom to its highest point."""
        return self.height + (KNOB[1] if self.knob else 0.0)

    def width(self, shape: str) -> float:
        """Its bounding width in workspace units when seen as `shape`."""
        across = self.size * (np.sqrt(2.0) if shape == "diamond" else 1.0)
        return float(across / WORKSPACE_SIDE)


KNOB = (0.016, 0.035)  # a plate's knob: side and height (metres), gripped like a small box

BODIES: tuple[Body, ...] = (
    Body("box_s", "box", 0.036, 0.035),
    Body("box_m", "box", 0.044, 0.040),
    Body("box_l", "box", 0.050, 0.030),
    Body("ball_s", "ball", 0.040, 0.040),
    Body("ball_l", "ball", 0.050, 0.050),
    Body("lemon", "lemon", 0.054, 0.042),
    Body("triangle", "triangle", 0.050, 0.012),
    Body("star", "star", 0.060, 0.012),
)
# Bodies that never stand on the table together need no contact (MJX computes every allowed
# pair every step, and hull against hull is the dearest): the three hulls never meet.
APART: tuple[tuple[str, str], ...] = (("lemon", "triangle"), ("lemon", "star"), ("triangle", "star"))

COLORS_RGB: dict[str, tuple[float, float, float]] = {
    "red": (0.85, 0.08, 0.08), "green": (0.10, 0.62, 0.18),
    "blue": (0.10, 0.25, 0.85), "yellow": (0.92, 0.80, 0.08),
}
TEXTURES: tuple[str, ...] = ("grey", "checker", "speckle", "gradient")
