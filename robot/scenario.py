"""Randomized tabletop scenarios for a concept: which bodies stand where, in which colour,
on which table texture, with which distractors.

A scenario is drawn as a VCC scene whose objects are bodies of the model (`world.BODIES`):
a body's kind fixes the shapes it can be seen as and its width. The concept's program
must run on the scene and move something; the objects stand apart by `GAP` so that the
open fingers fit between them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import mujoco
import numpy as np

from robot.mjcf import HOME, N_DISTRACTORS, knob_geom, parked_xy
from robot.world import APART, BODIES, COLORS_RGB, TEXTURES, WORKSPACE_SIDE, to_table
from vccjax.errors import SceneError
from vccjax.world.pairs import uses_pointer
from vccjax.machine.instructions import COLORS
from vccjax.machine.program import Program
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, SceneObject, scenes_match

GAP = 0.035 / WORKSPACE_SIDE  # workspace units between bounding boxes: the fingers' room
OBJECTS = (2, 5)


@dataclasses.dataclass(frozen=True)
class Scenario:
    scene: Scene  # the ground truth, in the VCC's terms
    slots: tuple[int, ...]  # body of each scene object
    texture: str
    distractors: tuple[tuple[float, float, float], ...]  # world (x, y, yaw) of each distractor
    seed: int

    def qpos(self, model: mujoco.MjModel) -> np.ndarray:
        """Initial joint positions: the arm at home, the scene's bodies on the table, the
        other bodies parked."""
        q = model.qpos0.copy()
        for j, v in zip(("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"), HOME):
            q[model.joint(j).qposadr[0]] = v
        for k, body in enumerate(BODIES):
            adr = model.joint(f"slot{k}").qposadr[0]
            x, y = parked_xy(k)
            yaw = 0.0
            if k in self.slots:
                o = self.scene.objects[self.slots.index(k)]
                x, y = to_table(o.x, o.y)
                yaw = np.pi / 4 if o.shape == "diamond" else 0.0
            q[adr:adr + 3] = (x, y, body.height / 2 + 1e-4)
            q[adr + 3:adr + 7] = (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))
        return q

    def dress(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """What only the camera sees: colours, texture, pointer and distractor places."""
        for k, body in enumerate(BODIES):
            for g in (f"obj{k}", knob_geom(k)) if body.knob else (f"obj{k}",):
                model.geom(g).rgba[:3] = COLORS_RGB[self.scene.objects[self.slots.index(k)].color] \
                    if k in self.slots else (0.5, 0.5, 0.5)
        model.geom("table_top").matid = model.material(f"table_{self.texture}").id
        pointer = model.body("pointer").mocapid[0]
        if self.scene.pointer is not None:
            data.mocap_pos[pointer] = (*to_table(*self.scene.pointer), 0.0005)
        else:
            data.mocap_pos[pointer] = (-1.0, 1.0, 0.0005)
        for k, (x, y, yaw) in enumerate(self.distractors):
            m = model.body(f"distractor{k}").mocapid[0]
            data.mocap_pos[m] = (x, y, 0.02)
            data.mocap_quat[m] = (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))


def draw(programs: Program | Sequence[Program], seed: int, objects: tuple[int, int] = OBJECTS,
         max_tries: int = 2000, shapes: tuple[str, ...] | None = None) -> Scenario:
    """A scenario on which the program (or each of a composition in turn) runs and which
    it changes; seeded."""
    programs = [programs] if isinstance(programs, Program) else list(programs)
    rng = np.random.default_rng([seed, 0x80B07])
    pointer = any(uses_pointer(p) for p in programs)
    for _ in range(max_tries):
        n = int(rng.integers(objects[0], objects[1] + 1))
        slots = tuple(int(k) for k in rng.choice(len(BODIES), n, replace=False))
        names = {BODIES[k].name for k in slots}
        if any(a in names and b in names for a, b in APART):
            continue
        objs = []
        for k in slots:
            choices = [s for s in BODIES[k].shapes if shapes is None or s in shapes] or list(BODIES[k].shapes)
            shape = str(rng.choice(choices))
            objs.append((shape, str(rng.choice(COLORS)), BODIES[k].width(shape)))
        placed = _place(rng, objs, pointer)
        if placed is None:
            continue
        out = placed
        for program in programs:
            m = RefMachine(out).run(program)
            if m.failed:
                break
            out = m.output_scene()
        if m.failed or scenes_match(out, placed, m.cfg.tau):
            continue
        scene = placed
        return Scenario(scene, slots, str(rng.choice(TEXTURES)), _distractors(rng), seed)
    raise SceneError(f"no scenario found in {max_tries} tries (seed {seed})")


def _place(rng: np.random.Generator, objs, pointer: bool) -> Scene | None:
    placed: list[SceneObject] = []
    for shape, color, w in objs:
        for _ in range(200):
            x, y = rng.uniform(w / 2 + 0.01, 1 - w / 2 - 0.01, 2)
            if all(max(abs(x - o.x) - (w + o.width) / 2, abs(y - o.y) - (w + o.width) / 2) >= GAP for o in placed):
                placed.append(SceneObject(shape, color, float(x), float(y), float(w)))
                break
        else:
            return None
    ptr = None
    if pointer:
        for _ in range(200):
            p = rng.uniform(0.08, 0.92, 2)
            if all(max(abs(p[0] - o.x), abs(p[1] - o.y)) - o.width / 2 >= 0.06 for o in placed):
                ptr = (float(p[0]), float(p[1]))
                break
        else:
            return None
    scene = Scene(tuple(placed), ptr)
    try:
        scene.validate()
    except SceneError:
        return None
    return scene


def _distractors(rng: np.random.Generator) -> tuple[tuple[float, float, float], ...]:
    """Pale boxes on the table in the camera's view but off the workspace square."""
    out = []
    for k in range(N_DISTRACTORS):
        side = rng.integers(3)
        along = rng.uniform(-0.15, 0.15)
        x, y = {0: (0.45 + along, 0.27), 1: (0.45 + along, -0.27), 2: (0.72, along)}[int(side)]
        out.append((float(x), float(y) + 0.01 * k, float(rng.uniform(0, np.pi))))
    return tuple(out)
