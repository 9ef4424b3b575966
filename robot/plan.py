"""From a VCC run to arm motions: which object is carried where, and along which path.

The program runs on the reference interpreter as usual, on the scene parsed from the
camera image. Only the hand's instructions reach the arm: each grab ... release becomes
one pick-and-place whose carry follows the machine's own straight segments (a carry
stops where the object would touch another or leave the workspace, so the path already
respects the world's contacts and boundary). Everything else stays in the VCC.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import cv2
import numpy as np

from robot.world import KNOB, WORKSPACE_SIDE
from vccjax.machine.config import VCCConfig
from vccjax.machine.geometry import object_pixels
from vccjax.machine.instructions import NAMES, SHAPES
from vccjax.machine.program import Program
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene

# instructions that move the held object (spec: carries); the rest never move the arm
_CARRIES = {"move_hand_left", "move_hand_right", "move_hand_up", "move_hand_down", "move_hand_to_pointer",
            "move_hand_to_fixate_collision", "move_hand_to_attended_object"}
NOT_ON_A_ROBOT = {"fill_color": "recolours an object", "remove_from_imagine_buffer": "removes an object"}


class PlanError(ValueError):
    """The program cannot be carried out by the arm (it failed, or it changes the scene
    in a way no hand can)."""


@dataclasses.dataclass(frozen=True)
class PickPlace:
    """One object carried: `path` lists its centre (workspace units, x right, y down) at
    the grab and after each carry that moved it; the last point is where it is released."""

    slot: int  # index of the object in the parsed scene
    shape: str
    width: float
    path: tuple[tuple[float, float], ...]
    around_pick: tuple[tuple[float, float, float, str], ...] = ()  # other objects (x, y, width, shape) at the grab
    around_place: tuple[tuple[float, float, float, str], ...] = ()  # ... and at the release


class _Tracer(RefMachine):
    """The reference machine, noting each executed instruction's effect on the hand
    (`execute` runs for every instruction, loop replays included)."""

    def __init__(self, scene: Scene):
        super().__init__(scene)
        self.moves: list[PickPlace] = []
        self._path: list[tuple[float, float]] = []

    def _others(self, i: int) -> tuple[tuple[float, float, float, str], ...]:
        return tuple((*self._centre_of(j), self.widths[j], SHAPES[self.shapes[j]])
                     for j in self.real_alive() if j != i)

    def _centre_of(self, i: int) -> tuple[float, float]:
        (x, y), u = self.centre(i), self.cfg.units
        return (x / u, y / u)

    def execute(self, op: int, arg: int) -> None:
        name = NAMES[op]
        if name in NOT_ON_A_ROBOT:
            raise PlanError(f"{name} {NOT_ON_A_ROBOT[name]}: not something an arm can do")
        super().execute(op, arg)
        held = self.hand.held
        if name == "grab_object":
            self._path = [self._centre_of(held)]
            self._around = self._others(held)
        elif name in _CARRIES and held >= 0:
            p = self._centre_of(held)
            if p != self._path[-1]:
                self._path.append(p)
        elif name == "release_object":
            self._finish()

    def _finish(self) -> None:
        i = self._held_before_release
        o = self.scene.objects[i]
        if len(self._path) > 1:  # a grab and release without a carry moves nothing
            self.moves.append(PickPlace(i, o.shape, o.width, tuple(self._path), self._around, self._others(i)))
        self._path = []

    def op_release_object(self, arg: int) -> None:
        self._held_before_release = self.hand.held
        super().op_release_object(arg)


def plan(programs: Program | Sequence[Program], scene: Scene) -> tuple[list[PickPlace], Scene]:
    """The pick-and-places that carry the program out on `scene`, and the VCC's output
    scene (what the table should look like at the end). Several programs are composed:
    each runs, on a fresh machine, on the scene the one before left (the paper's
    composition of learned concepts)."""
    moves: list[PickPlace] = []
    for k, program in enumerate([programs] if isinstance(programs, Program) else programs):
        m = _Tracer(scene)
        for op, arg in zip(program.ops, program.args):
            m.step(op, arg)
            if m.failed:
                where = f" of program {k + 1}" if k else ""
                raise PlanError(f"the program failed at instruction {m.control.fail_index}{where} on the parsed scene: "
                                f"{m.fail_reason}")
        if m.hand.held >= 0:  # the VCC may end holding: the arm puts it down where it is
            m._held_before_release = m.hand.held
            m._finish()
        moves += m.moves
        scene = m.output_scene()
    return moves, scene


PAD = 0.012 / WORKSPACE_SIDE  # an open pad's reach beyond its gap, workspace units
ROOM = 0.012 / WORKSPACE_SIDE  # gap between an open pad and the gripped object


def grip_yaw(mv: PickPlace) -> float:
    """Finger axis (radians from world +x): across two parallel faces of the object, and
    of those the one whose pads keep farthest from every other object at the grab, along
    the carry and at the release (ties: square to the last leg of the path)."""
    if mv.shape == "circle":
        choices = list(np.linspace(0, np.pi, 8, endpoint=False))
    elif mv.shape == "square":
        choices = [0.0, np.pi / 2]
    elif mv.shape == "diamond":
        choices = [np.pi / 4, 3 * np.pi / 4]
    elif mv.shape in ("triangle", "star"):
        choices = [0.0, np.pi / 2]  # across the plate's square knob
    else:
        raise PlanError(f"no grasp for a {mv.shape}")
    (u0, v0), (u1, v1) = mv.path[-2], mv.path[-1]
    heading = float(np.arctan2(-(u1 - u0), -(v1 - v0)))  # world angle of the last leg (x = -v, y = -u)
    if mv.shape in ("triangle", "star"):
        across = KNOB[0] / WORKSPACE_SIDE
    else:
        across = mv.width / (np.sqrt(2.0) if mv.shape == "diamond" else 1.0)
    half = across / 2 + ROOM + PAD / 2

    def clearance(yaw: float) -> float:
        du, dv = -np.sin(yaw), -np.cos(yaw)  # the finger axis in workspace terms
        worst = np.inf
        # the grab, points along the carry (the others stand still meanwhile), and the release
        legs = [np.array(mv.path[i]) + f * (np.array(mv.path[i + 1]) - np.array(mv.path[i]))
                for i in range(len(mv.path) - 1) for f in np.linspace(0, 1, 6)[1:-1]]
        for centre, around in ((mv.path[0], mv.around_pick), *((c, mv.around_pick) for c in legs),
                               (mv.path[-1], mv.around_place)):
            for sign in (1, -1):
                pu, pv = centre[0] + sign * half * du, centre[1] + sign * half * dv
                for x, y, w, _ in around:
                    gap = max(abs(pu - x) - w / 2, abs(pv - y) - w / 2, 0.0)
                    worst = min(worst, gap - PAD / 2)
        return worst

    best = max(choices, key=lambda a: (round(min(clearance(a), 0.1), 3), abs(np.sin(a - heading))))
    return float((best + np.pi / 2) % np.pi - np.pi / 2)  # fingers are symmetric: yaw and yaw + pi agree


FINE = VCCConfig(raster=512, sub=4)  # a fine raster for physical clearances (0.8 mm pixels)
CLEARANCE = 0.003 / WORKSPACE_SIDE  # what a placed object keeps from the others
MAX_SHIFT = 0.008 / WORKSPACE_SIDE


def set_down_clear(mv: PickPlace) -> tuple[float, float]:
    """Where to release the object: the VCC's place, moved up to 8 mm away from its
    neighbours where they are nearer than 3 mm. The machine's 64-pixel raster lets shapes
    that touch on it overlap by up to a pixel (6 mm of table), and a ball set down into
    another would roll away. The move stays well within the success tolerance."""
    u, size = FINE.units, FINE.raster
    others = np.zeros((size, size), np.uint8)
    for x, y, w, shape in mv.around_place:
        rows, cols = _inside(*object_pixels(shape, w, int(round(x * u)), int(round(y * u)), FINE))
        others[rows, cols] = 1
    if not others.any():
        return mv.path[-1]
    dist = cv2.distanceTransform(1 - others, cv2.DIST_L2, 5) / size  # workspace units to the nearest other
    grad_y, grad_x = np.gradient(dist)
    here = np.array(mv.path[-1], float)
    for _ in range(16):
        rows, cols = _inside(*object_pixels(mv.shape, mv.width, int(round(here[0] * u)), int(round(here[1] * u)), FINE))
        near = dist[rows, cols] < CLEARANCE
        if not near.any():
            break
        away = np.array([grad_x[rows[near], cols[near]].sum(), grad_y[rows[near], cols[near]].sum()])
        if not np.linalg.norm(away):
            break
        step = here + away / np.linalg.norm(away) * (MAX_SHIFT / 8)
        step = np.clip(step, mv.width / 2, 1 - mv.width / 2)
        if np.linalg.norm(step - np.array(mv.path[-1])) > MAX_SHIFT:
            break
        here = step
    return (float(here[0]), float(here[1]))


def _inside(rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    keep = (rows >= 0) & (rows < FINE.raster) & (cols >= 0) & (cols < FINE.raster)
    return rows[keep], cols[keep]
