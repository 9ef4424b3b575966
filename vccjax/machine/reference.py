"""The scalar reference interpreter: plain Python/NumPy, written to be read.

It is the oracle the JAX emulator is tested against and the baseline of the
benchmarks. Every rule of docs/vcc.md sections 2-5 appears here once, in the order of
the instruction table of section 3.
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.geometry import imagined_pixels, object_pixels
from vccjax.machine.instructions import (
    COLORS,
    FIXATE_TARGETS,
    FORBIDDEN_IN_LOOP,
    NAMES,
    REQUIRED_IN_LOOP,
    SHAPES,
)
from vccjax.machine.program import Program
from vccjax.machine.scene import Scene, SceneObject, box_inside, to_units


@dataclasses.dataclass
class RefObject:
    shape: int
    color: int
    x: int  # centre, integer position units
    y: int
    width: float
    alive: bool = True


class Failure(Exception):
    """Raised inside an instruction; the machine records it and stops."""


class RefMachine:
    """One VCC running on one scene."""

    def __init__(self, scene: Scene, cfg: VCCConfig = DEFAULT_CONFIG, validate: bool = True):
        if validate:
            scene.validate(cfg)
        self.cfg = cfg
        self.scene = scene
        u = cfg.units
        centre = (u // 2, u // 2)
        self.parsed = False
        self.objects: list[RefObject] = []
        self.pointer: tuple[int, int] | None = None
        self.imagined: tuple[int, int, int] | None = None  # (kind, x, y)
        self.fovea = centre
        self.history = [centre]
        self.h = 0
        self.hand = centre
        self.held: int | None = None
        self.shape_filter: int | None = None
        self.color_filter: int | None = None
        self.attended_list: list[int] = []
        self.stale = True
        self.k = 0
        self.attended: int | None = None
        self.failed = False
        self.fail_index: int | None = None
        self.fail_reason: str | None = None
        self.pc = 0
        self.in_loop = False
        self.loop_active = False
        self.body: list[tuple[int, int, int]] = []  # (op, arg, program index)
        self.watch = None  # called as watch(machine, op, arg, pc) after each instruction (vccjax.views.trace)

    def clone(self) -> RefMachine:
        """An independent copy (the scene, read-only, is shared): a search keeps one per prefix."""
        m = copy.copy(self)
        m.objects = [dataclasses.replace(o) for o in self.objects]
        m.history = list(self.history)
        m.attended_list = list(self.attended_list)
        m.body = list(self.body)
        return m

    # ---- running ------------------------------------------------------------------------
    def run(self, program: Program) -> RefMachine:
        for op, arg in zip(program.ops, program.args):
            self.step(op, arg)
            if self.failed:
                break
        return self

    def step(self, op: int, arg: int = 0) -> None:
        """Take the next program instruction (with the loop bookkeeping of docs/vcc.md section 5)."""
        if self.failed:
            return
        pc = self.pc
        self.pc += 1
        name = NAMES[op]
        try:
            if self.in_loop and name != "loop_end":
                if name in FORBIDDEN_IN_LOOP:
                    raise Failure(f"{name} is not allowed in a loop body")
                if len(self.body) >= self.cfg.body_max:
                    raise Failure(f"loop body longer than body_max={self.cfg.body_max}")
                self.body.append((op, arg, pc))
                if not self.loop_active:  # zero iterations: the body is only recorded
                    return
            self.execute(op, arg)
        except Failure as f:
            self.failed, self.fail_index, self.fail_reason = True, pc, str(f)
        if self.watch is not None and (not self.failed or self.fail_index == pc):
            self.watch(self, op, arg, pc)

    def execute(self, op: int, arg: int) -> None:
        name = NAMES[op]
        if not self.parsed and name != "scene_parse":
            raise Failure("no scene parsed yet")
        getattr(self, "op_" + name)(arg)

    # ---- helpers ------------------------------------------------------------------------
    def centre(self, i: int) -> tuple[int, int]:
        o = self.objects[i]
        return o.x, o.y

    def pixels(self, i: int) -> set[tuple[int, int]]:
        o = self.objects[i]
        rows, cols = object_pixels(o.shape, o.width, o.x, o.y, self.cfg)
        return set(zip(rows.tolist(), cols.tolist()))

    def imagined_set(self) -> set[tuple[int, int]]:
        if self.imagined is None:
            return set()
        rows, cols = imagined_pixels(*self.imagined, self.cfg)
        return set(zip(rows.tolist(), cols.tolist()))

    def real_alive(self) -> list[int]:
        return [i for i, o in enumerate(self.objects) if o.alive]

    def pixel_of(self, p: tuple[int, int]) -> tuple[int, int]:
        last = self.cfg.raster - 1
        return min(p[1] // self.cfg.sub, last), min(p[0] // self.cfg.sub, last)

    def object_at(self, p: tuple[int, int]) -> int | None:
        pix = self.pixel_of(p)
        for i in self.real_alive():
            if pix in self.pixels(i):
                return i
        return None

    def refresh(self) -> None:
        if not self.stale:
            return
        fx, fy = self.fovea

        def passes(i: int) -> bool:
            o = self.objects[i]
            return (self.shape_filter is None or o.shape == self.shape_filter) and (
                self.color_filter is None or o.color == self.color_filter
            )

        ids = [i for i in self.real_alive() if passes(i)]
        self.attended_list = sorted(
            ids, key=lambda i: ((self.objects[i].x - fx) ** 2 + (self.objects[i].y - fy) ** 2, i)
        )
        self.stale = False

    def fixate_on(self, p: tuple[int, int]) -> None:
        if len(self.history) >= self.cfg.hist_max:
            raise Failure(f"fixation history full ({self.cfg.hist_max})")
        self.history.append(p)
        self.h = len(self.history) - 1
        self.fovea = p

    def need_held(self) -> int:
        if self.held is None:
            raise Failure("not holding an object")
        return self.held

    def need_attended(self) -> int:
        if self.attended is None:
            raise Failure("no attended object")
        return self.attended

    def carry(self, path: list[tuple[int, int]]) -> None:
        """Move the held object along pixel offsets path[0]=(0,0), path[1], ...; stop before
        the first offset where it would overlap another object or its w x w box would
        leave the workspace."""
        i = self.need_held()
        o = self.objects[i]
        s = self.cfg.sub
        w = to_units(o.width, self.cfg)
        # the other objects' and the imagined pixels on a raster with a wide margin (masks
        # may reach past the workspace); the held object moves by whole pixels, so its
        # mask at offset (dx, dy) is its mask now shifted by (dy, dx) rows and columns
        m = 2 * self.cfg.raster
        blocked = np.zeros((5 * self.cfg.raster,) * 2, bool)
        if self.imagined is not None:
            rows, cols = imagined_pixels(*self.imagined, self.cfg)
            blocked[rows + m, cols + m] = True
        for j in self.real_alive():
            if j != i:
                q = self.objects[j]
                rows, cols = object_pixels(q.shape, q.width, q.x, q.y, self.cfg)
                blocked[rows + m, cols + m] = True
        rows, cols = object_pixels(o.shape, o.width, o.x, o.y, self.cfg)
        steps = np.asarray(path[1:], np.int64).reshape(-1, 2)
        hits = blocked[rows[None, :] + m + steps[:, 1:], cols[None, :] + m + steps[:, :1]].any(axis=1)
        last = (0, 0)
        for (dx, dy), hit in zip(steps.tolist(), hits.tolist()):
            if hit or not box_inside(o.x + dx * s, o.y + dy * s, w, self.cfg):
                break
            last = (dx, dy)
        o.x += last[0] * s
        o.y += last[1] * s
        self.hand = (self.hand[0] + last[0] * s, self.hand[1] + last[1] * s)

    def carry_toward(self, target: tuple[int, int]) -> None:
        i = self.need_held()
        s = self.cfg.sub
        ox, oy = self.centre(i)
        # displacement in whole pixels, rounded half up; samples rounded half up along it
        dpx = (2 * (target[0] - ox) + s) // (2 * s)
        dpy = (2 * (target[1] - oy) + s) // (2 * s)
        n = max(abs(dpx), abs(dpy))
        path = [(0, 0)] + [
            ((2 * t * dpx + n) // (2 * n), (2 * t * dpy + n) // (2 * n)) for t in range(1, n + 1)
        ]
        self.carry(path)

    def carry_direction(self, ux: int, uy: int) -> None:
        self.need_held()
        self.carry([(t * ux, t * uy) for t in range(self.cfg.raster + 1)])

    # ---- instructions (docs/vcc.md section 3) ----------------------------------------------
    def op_scene_parse(self, arg: int) -> None:
        if self.parsed:
            raise Failure("scene_parse is not first")
        self.parsed = True
        self.objects = [
            RefObject(SHAPES.index(o.shape), COLORS.index(o.color),
                      to_units(o.x, self.cfg), to_units(o.y, self.cfg), float(o.width))
            for o in self.scene.objects
        ]
        if self.scene.pointer is not None:
            self.pointer = (to_units(self.scene.pointer[0], self.cfg),
                            to_units(self.scene.pointer[1], self.cfg))

    def _set_filter(self, which: str, arg: int) -> None:
        if getattr(self, which) is not None:
            raise Failure(f"{which.replace('_', ' ')} already set")
        setattr(self, which, arg)
        self.stale, self.k, self.attended = True, 0, None

    def op_set_shape_attn(self, arg: int) -> None:
        self._set_filter("shape_filter", arg)

    def op_set_color_attn(self, arg: int) -> None:
        self._set_filter("color_filter", arg)

    def op_reset_attn(self, arg: int) -> None:
        self.shape_filter = self.color_filter = None
        self.stale, self.k, self.attended = True, 0, None

    def op_top_down_attend(self, arg: int) -> None:
        self.refresh()
        if self.k >= len(self.attended_list):
            raise Failure(f"cursor {self.k} past the {len(self.attended_list)} attended objects")
        self.attended = self.attended_list[self.k]

    def op_next_object(self, arg: int) -> None:
        self.refresh()
        self.k += 1
        self.attended = None
        if self.k > len(self.attended_list):
            raise Failure(f"cursor {self.k} beyond the {len(self.attended_list)} attended objects")

    def op_attend_pointer(self, arg: int) -> None:
        if self.pointer is None:
            raise Failure("no pointer")
        i = self.object_at(self.pointer)
        if i is None:
            raise Failure("no object under the pointer")
        self.attended = i

    def op_fixate(self, arg: int) -> None:
        u = self.cfg.units
        target = {
            "left": (0, u // 2), "right": (u, u // 2), "top": (u // 2, 0),
            "bottom": (u // 2, u), "center": (u // 2, u // 2),
        }[FIXATE_TARGETS[arg]]
        self.fixate_on(target)

    def op_fixate_attended_object(self, arg: int) -> None:
        self.fixate_on(self.centre(self.need_attended()))

    def op_fixate_pointer(self, arg: int) -> None:
        if self.pointer is None:
            raise Failure("no pointer")
        self.fixate_on(self.pointer)

    def op_fixate_previous(self, arg: int) -> None:
        if self.h == 0:
            raise Failure("no previous fixation")
        self.h -= 1
        self.fovea = self.history[self.h]

    def op_fixate_next(self, arg: int) -> None:
        if self.h == len(self.history) - 1:
            raise Failure("no next fixation")
        self.h += 1
        self.fovea = self.history[self.h]

    def op_move_hand_to_attended_object(self, arg: int) -> None:
        a = self.need_attended()
        if self.held is None:
            self.hand = self.centre(a)
        elif a == self.held:
            raise Failure("the attended object is the held object")
        else:
            self.carry_toward(self.centre(a))

    def op_grab_object(self, arg: int) -> None:
        if self.held is not None:
            raise Failure("already holding an object")
        i = self.object_at(self.hand)
        if i is None:
            raise Failure("no object at the hand")
        self.held = i

    def op_release_object(self, arg: int) -> None:
        self.need_held()
        self.held = None

    def op_move_hand_left(self, arg: int) -> None:
        self.carry_direction(-1, 0)

    def op_move_hand_right(self, arg: int) -> None:
        self.carry_direction(1, 0)

    def op_move_hand_up(self, arg: int) -> None:
        self.carry_direction(0, -1)

    def op_move_hand_down(self, arg: int) -> None:
        self.carry_direction(0, 1)

    def op_move_hand_to_pointer(self, arg: int) -> None:
        self.need_held()
        if self.pointer is None:
            raise Failure("no pointer")
        self.carry_toward(self.pointer)

    def op_move_hand_to_fixate_collision(self, arg: int) -> None:
        self.need_held()
        self.carry_toward(self.fovea)

    def op_fill_color(self, arg: int) -> None:
        self.objects[self.need_attended()].color = arg

    def op_remove_from_imagine_buffer(self, arg: int) -> None:
        a = self.need_attended()
        self.objects[a].alive = False
        if self.held == a:
            self.held = None
        self.attended, self.stale = None, True

    def op_imagine_object(self, arg: int) -> None:
        if self.imagined is not None:
            raise Failure("an imagined object exists")
        footprint = imagined_pixels(arg, self.fovea[0], self.fovea[1], self.cfg)
        footprint = set(zip(footprint[0].tolist(), footprint[1].tolist()))
        for i in self.real_alive():
            if footprint & self.pixels(i):
                raise Failure("the imagined object would overlap an object")
        self.imagined = (arg, self.fovea[0], self.fovea[1])

    def op_reset_imagination(self, arg: int) -> None:
        if self.imagined is None:
            raise Failure("no imagined object")
        self.imagined = None

    def op_loop_start(self, arg: int) -> None:
        self.refresh()
        self.in_loop = True
        self.loop_active = self.k < len(self.attended_list)
        self.body = []

    def op_loop_end(self, arg: int) -> None:
        if not self.in_loop:
            raise Failure("loop_end without loop_start")
        names = {NAMES[op] for op, _, _ in self.body}
        if not REQUIRED_IN_LOOP <= names:
            raise Failure("loop body lacks top_down_attend or next_object")
        self.in_loop = False
        if not self.loop_active:
            return
        iterations = 1  # the first ran eagerly
        while iterations < self.cfg.n_max and self.k < len(self.attended_list):
            for op, arg, pc in self.body:
                try:
                    self.execute(op, arg)
                except Failure as f:
                    self.failed, self.fail_index, self.fail_reason = True, pc, str(f)
                if self.watch is not None:
                    self.watch(self, op, arg, pc)
                if self.failed:
                    return
            iterations += 1

    # ---- results ------------------------------------------------------------------------
    def output_scene(self) -> Scene:
        u = self.cfg.units
        objs = tuple(
            SceneObject(SHAPES[o.shape], COLORS[o.color], o.x / u, o.y / u, o.width)
            for o in self.objects if o.alive
        )
        return Scene(objs, self.scene.pointer)


def run_reference(program: Program, scene: Scene, cfg: VCCConfig = DEFAULT_CONFIG) -> RefMachine:
    """Run a program on a scene; the machine holds status, failing index and output."""
    return RefMachine(scene, cfg).run(program)
