"""Pick-and-places (workspace units) to the arm's keyframes (world metres, control ticks).

Per object: move above it with the fingers open and turned to the grasp yaw, descend,
close, lift a little, carry along the VCC's path, lower, open, rise. Speeds are
modest, so that a held object does not slip and the servos keep up.
"""

from __future__ import annotations

import numpy as np

from robot.control import TICK, Keyframes
from robot.mjcf import FINGER_OPEN
from robot.plan import PickPlace, grip_yaw, set_down_clear
from robot.world import BODIES, KNOB, WORKSPACE_SIDE, to_table

PLATES = {b.kind: b for b in BODIES if b.knob}  # the shapes only a knobbed plate stands for
TIPS_BELOW_TCP = 0.015  # the pads' tips below the tool centre point (robot/mjcf.py)

SAFE_Z = 0.13  # tool centre above the table when moving between objects
GRASP_Z = 0.018  # tool centre when closing on an object (pads end 1.5 cm lower)
CARRY_LIFT = 0.02  # the carried object's clearance above the table (6.5 cm, over every other object,
# let held boxes tip in the grip: 86 of 128 rollouts against 116)
SPEED = 0.25  # m/s of the target, horizontal
CARRY_SPEED = 0.15  # m/s while carrying (0.25 with a 3 cm lift lost more grasps: 87 of 96 against 93)
VERTICAL = 0.15  # m/s
TURN = 2.0  # rad/s of yaw
CLOSE_S, OPEN_S, SETTLE_S = 0.5, 0.4, 0.3
FINGER_ROOM = 0.012  # metres between an open pad and the object it grips
GRIP_CLOSED = 0.0  # commanded opening when closed: the servo squeezes with ~kp x half the object's width
MAX_KEYFRAMES = 96


def _world(p) -> np.ndarray:
    return np.asarray(to_table(p[0], p[1]), float)


def keyframes(moves: list[PickPlace], start: np.ndarray, start_yaw: float = 0.0,
              max_keyframes: int = MAX_KEYFRAMES) -> tuple[Keyframes, int, list[tuple[int, int]]]:
    """Keyframes for `moves` from the tool pose `start` (x, y, z); the tick at which the
    last is reached; and per move the ticks between which its object should be held
    aloft (lifted and settled .. lowering begins)."""
    rows: list[tuple[float, np.ndarray, float, float]] = []  # (seconds, pos, yaw, grip)
    pos, yaw, grip = np.asarray(start, float), float(start_yaw), FINGER_OPEN
    rows.append((0.0, pos, yaw, grip))

    def go(target, new_yaw=None, new_grip=None, hold=0.0, speed=SPEED):
        nonlocal pos, yaw, grip
        target = np.asarray(target, float)
        if new_yaw is None:
            new_yaw = yaw
        else:  # the nearest equivalent turn, kept within half a turn of the start (the wrist's range)
            new_yaw = _nearest(new_yaw, yaw)
            new_yaw -= np.pi * np.round((new_yaw - start_yaw) / (2 * np.pi) * 0.999)
        dist = np.linalg.norm(target[:2] - pos[:2]) / speed + abs(target[2] - pos[2]) / VERTICAL
        seconds = max(dist, abs(new_yaw - yaw) / TURN, hold, TICK)
        pos, yaw, grip = target, new_yaw, grip if new_grip is None else new_grip
        rows.append((rows[-1][0] + seconds, pos, yaw, grip))

    if pos[2] < SAFE_Z:
        go([*pos[:2], SAFE_Z])
    held: list[tuple[float, float]] = []
    for mv in moves:
        pts = [_world(p) for p in (*mv.path[:-1], set_down_clear(mv))]
        y = grip_yaw(mv)
        open_to = min(FINGER_OPEN, across(mv.shape, mv.width) / 2 + FINGER_ROOM)
        z = grasp_z(mv.shape, mv.width)
        go([*pts[0], SAFE_Z], y, open_to)
        go([*pts[0], z])
        go([*pts[0], z], new_grip=GRIP_CLOSED, hold=CLOSE_S)
        go([*pts[0], z + CARRY_LIFT], hold=SETTLE_S)
        aloft = rows[-1][0]
        for p in pts[1:]:
            go([*p, z + CARRY_LIFT], speed=CARRY_SPEED)
        held.append((aloft, rows[-1][0]))
        go([*pts[-1], z + 0.002], hold=SETTLE_S)
        go([*pts[-1], z + 0.002], new_grip=open_to, hold=OPEN_S)
        go([*pts[-1], SAFE_Z])
    go(pos, hold=SETTLE_S)  # come to rest
    if len(rows) > max_keyframes:
        raise ValueError(f"{len(rows)} keyframes, more than the rollout's {max_keyframes}")
    ticks = np.round(np.array([r[0] for r in rows]) / TICK).astype(np.int32)
    ticks = np.maximum.accumulate(np.maximum(ticks, np.arange(len(ticks))))  # strictly increasing
    pad = max_keyframes - len(rows)
    kf = Keyframes(
        tick=np.concatenate([ticks, ticks[-1] + 1 + np.arange(pad)]).astype(np.int32),
        pos=np.concatenate([np.stack([r[1] for r in rows]), np.repeat(rows[-1][1][None], pad, 0)]).astype(np.float32),
        yaw=np.array([r[2] for r in rows] + [rows[-1][2]] * pad, np.float32),
        grip=np.array([r[3] for r in rows] + [rows[-1][3]] * pad, np.float32))
    windows = [(int(round(a / TICK)), int(round(b / TICK))) for a, b in held]
    return kf, int(ticks[-1]), windows


def grasp_z(shape: str, width: float) -> float:
    """Tool centre height for the grasp: a round object at its equator as seen from above
    (a ball is as tall as it is wide), a plate (triangle, star) by its knob with the pads'
    tips 4 mm above the plate, anything else at `GRASP_Z`."""
    if shape == "circle":
        return float(np.clip(width * WORKSPACE_SIDE / 2, GRASP_Z, 0.026))
    if shape in PLATES:
        return PLATES[shape].height + 0.004 + TIPS_BELOW_TCP
    return GRASP_Z


def across(shape: str, width: float) -> float:
    """Metres between the faces the fingers close on (a diamond is gripped across its
    sides, a plate across its knob)."""
    if shape in PLATES:
        return KNOB[0]
    return width * WORKSPACE_SIDE / (np.sqrt(2.0) if shape == "diamond" else 1.0)


def _nearest(a: float, ref: float) -> float:
    """The angle equal to `a` modulo pi (the fingers are symmetric) nearest to `ref`."""
    return float(a + np.pi * np.round((ref - a) / np.pi))
