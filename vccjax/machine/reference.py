"""The scalar reference interpreter: plain Python/NumPy, written to be read.

It is the oracle the JAX emulator is tested against and the baseline of the
benchmarks. Every rule of docs/vcc.md sections 2-5 appears here once, in the order of
the instruction table of section 3. It holds the same five memories as the JAX state,
under the same names (`memories.py`), in plain Python.
"""

from __future__ import annotations

import copy

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
from vccjax.machine.memories import MEMORIES, Attention, Blackboard, Control, Fovea, Hand, copied
from vccjax.machine.program import Program
from vccjax.machine.reference_motion import carry, straight, toward
from vccjax.machine.scene import Scene, SceneObject, to_units


class Failure(Exception):
    """Raised inside an instruction; the machine records it and stops."""


class RefMachine:
    """One VCC running on one scene: the scene's constants and the five memories."""

    def __init__(self, scene: Scene, cfg: VCCConfig = DEFAULT_CONFIG, validate: bool = True):
        if validate:
            scene.validate(cfg)
        self.cfg = cfg
        self.scene = scene
        # what the scene fixes, per object slot: shape, width, centre at load (position units)
        self.shapes = [SHAPES.index(o.shape) for o in scene.objects]
        self.widths = [float(o.width) for o in scene.objects]
        self.bases = [(to_units(o.x, cfg), to_units(o.y, cfg)) for o in scene.objects]
        self.pointer = None if scene.pointer is None else (to_units(scene.pointer[0], cfg),
                                                           to_units(scene.pointer[1], cfg))
        centre = (cfg.units // 2, cfg.units // 2)
        n = max(cfg.n_max, len(scene.objects))  # n_max slots (an unvalidated scene may hold more)
        self.blackboard = Blackboard(parsed=False, alive=[False] * n, color=[0] * n, offset=[(0, 0)] * n,
                                     imagined_kind=-1, imagined_position=(0, 0))
        self.fovea = Fovea(position=centre, history=[centre], history_index=0)
        self.attention = Attention(shape_filter=-1, color_filter=-1, attended_list=[], stale=True,
                                   cursor=0, attended=-1)
        self.hand = Hand(position=centre, held=-1)
        self.control = Control(failed=False, fail_index=-1, pc=0, in_loop=False, loop_active=False,
                               body_ops=[], body_args=[], body_pc0=0)
        self.fail_reason: str | None = None
        self.watch = None  # called as watch(machine, op, arg, pc) after each instruction (vccjax.views.trace)

    @property
    def failed(self) -> bool:
        return self.control.failed

    def clone(self) -> RefMachine:
        """An independent copy (the scene, read-only, is shared): a search keeps one per prefix."""
        m = copy.copy(self)
        for name in MEMORIES:
            setattr(m, name, copied(getattr(self, name)))
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
        ctl = self.control
        if ctl.failed:
            return
        pc = ctl.pc
        ctl.pc += 1
        name = NAMES[op]
        try:
            if ctl.in_loop and name != "loop_end":
                if name in FORBIDDEN_IN_LOOP:
                    raise Failure(f"{name} is not allowed in a loop body")
                if len(ctl.body_ops) >= self.cfg.body_max:
                    raise Failure(f"loop body longer than body_max={self.cfg.body_max}")
                ctl.body_ops.append(op)
                ctl.body_args.append(arg)
                if not ctl.loop_active:  # zero iterations: the body is only recorded
                    return
            self.execute(op, arg)
        except Failure as f:
            self.fail(pc, f)
        if self.watch is not None and (not ctl.failed or ctl.fail_index == pc):
            self.watch(self, op, arg, pc)

    def fail(self, pc: int, f: Failure) -> None:
        self.control.failed, self.control.fail_index, self.fail_reason = True, pc, str(f)

    def execute(self, op: int, arg: int) -> None:
        name = NAMES[op]
        if not self.blackboard.parsed and name != "scene_parse":
            raise Failure("no scene parsed yet")
        getattr(self, "op_" + name)(arg)

    # ---- helpers ------------------------------------------------------------------------
    def centre(self, i: int) -> tuple[int, int]:
        (x, y), (dx, dy), s = self.bases[i], self.blackboard.offset[i], self.cfg.sub
        return x + dx * s, y + dy * s

    def object_pixels(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        return object_pixels(SHAPES[self.shapes[i]], self.widths[i], *self.centre(i), self.cfg)

    def pixels(self, i: int) -> set[tuple[int, int]]:
        rows, cols = self.object_pixels(i)
        return set(zip(rows.tolist(), cols.tolist()))

    def imagined_set(self) -> set[tuple[int, int]]:
        b = self.blackboard
        if b.imagined_kind < 0:
            return set()
        rows, cols = imagined_pixels(b.imagined_kind, *b.imagined_position, self.cfg)
        return set(zip(rows.tolist(), cols.tolist()))

    def real_alive(self) -> list[int]:
        return [i for i, alive in enumerate(self.blackboard.alive) if alive]

    def pixel_of(self, p: tuple[int, int]) -> tuple[int, int]:
        last = self.cfg.raster - 1
        return min(p[1] // self.cfg.sub, last), min(p[0] // self.cfg.sub, last)

    def object_at(self, p: tuple[int, int]) -> int:
        """The alive object whose mask holds the pixel of p, or -1."""
        pix = self.pixel_of(p)
        return next((i for i in self.real_alive() if pix in self.pixels(i)), -1)

    def refresh(self) -> None:
        a = self.attention
        if not a.stale:
            return
        fx, fy = self.fovea.position

        def passes(i: int) -> bool:
            return (a.shape_filter < 0 or self.shapes[i] == a.shape_filter) and (
                a.color_filter < 0 or self.blackboard.color[i] == a.color_filter
            )

        def key(i: int) -> tuple[int, int]:
            x, y = self.centre(i)
            return (x - fx) ** 2 + (y - fy) ** 2, i

        a.attended_list = sorted((i for i in self.real_alive() if passes(i)), key=key)
        a.stale = False

    def fixate_on(self, p: tuple[int, int]) -> None:
        f = self.fovea
        if len(f.history) >= self.cfg.hist_max:
            raise Failure(f"fixation history full ({self.cfg.hist_max})")
        f.history.append(p)
        f.history_index = len(f.history) - 1
        f.position = p

    def need_held(self) -> int:
        if self.hand.held < 0:
            raise Failure("not holding an object")
        return self.hand.held

    def need_attended(self) -> int:
        if self.attention.attended < 0:
            raise Failure("no attended object")
        return self.attention.attended

    def carry_toward(self, target: tuple[int, int]) -> None:
        i = self.need_held()
        carry(self, i, toward(self.centre(i), target, self.cfg))

    def carry_direction(self, ux: int, uy: int) -> None:
        carry(self, self.need_held(), straight(ux, uy, self.cfg))

    # ---- instructions (docs/vcc.md section 3) ----------------------------------------------
    def op_scene_parse(self, arg: int) -> None:
        b = self.blackboard
        if b.parsed:
            raise Failure("scene_parse is not first")
        b.parsed = True
        n = len(self.scene.objects)
        b.alive = [i < n for i in range(len(b.alive))]
        b.color = [COLORS.index(o.color) for o in self.scene.objects] + [0] * (len(b.alive) - n)
        b.offset = [(0, 0)] * len(b.alive)

    def _set_filter(self, which: str, arg: int) -> None:
        if getattr(self.attention, which) >= 0:
            raise Failure(f"{which.replace('_', ' ')} already set")
        setattr(self.attention, which, arg)
        self._unattend()

    def _unattend(self) -> None:
        self.attention.stale, self.attention.cursor, self.attention.attended = True, 0, -1

    def op_set_shape_attn(self, arg: int) -> None:
        self._set_filter("shape_filter", arg)

    def op_set_color_attn(self, arg: int) -> None:
        self._set_filter("color_filter", arg)

    def op_reset_attn(self, arg: int) -> None:
        self.attention.shape_filter = self.attention.color_filter = -1
        self._unattend()

    def op_top_down_attend(self, arg: int) -> None:
        self.refresh()
        a = self.attention
        if a.cursor >= len(a.attended_list):
            raise Failure(f"cursor {a.cursor} past the {len(a.attended_list)} attended objects")
        a.attended = a.attended_list[a.cursor]

    def op_next_object(self, arg: int) -> None:
        self.refresh()
        a = self.attention
        a.cursor += 1
        a.attended = -1
        if a.cursor > len(a.attended_list):
            raise Failure(f"cursor {a.cursor} beyond the {len(a.attended_list)} attended objects")

    def op_attend_pointer(self, arg: int) -> None:
        if self.pointer is None:
            raise Failure("no pointer")
        i = self.object_at(self.pointer)
        if i < 0:
            raise Failure("no object under the pointer")
        self.attention.attended = i

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
        f = self.fovea
        if f.history_index == 0:
            raise Failure("no previous fixation")
        f.history_index -= 1
        f.position = f.history[f.history_index]

    def op_fixate_next(self, arg: int) -> None:
        f = self.fovea
        if f.history_index == len(f.history) - 1:
            raise Failure("no next fixation")
        f.history_index += 1
        f.position = f.history[f.history_index]

    def op_move_hand_to_attended_object(self, arg: int) -> None:
        a = self.need_attended()
        if self.hand.held < 0:
            self.hand.position = self.centre(a)
        elif a == self.hand.held:
            raise Failure("the attended object is the held object")
        else:
            self.carry_toward(self.centre(a))

    def op_grab_object(self, arg: int) -> None:
        if self.hand.held >= 0:
            raise Failure("already holding an object")
        i = self.object_at(self.hand.position)
        if i < 0:
            raise Failure("no object at the hand")
        self.hand.held = i

    def op_release_object(self, arg: int) -> None:
        self.need_held()
        self.hand.held = -1

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
        self.carry_toward(self.fovea.position)

    def op_fill_color(self, arg: int) -> None:
        self.blackboard.color[self.need_attended()] = arg

    def op_remove_from_imagine_buffer(self, arg: int) -> None:
        a = self.need_attended()
        self.blackboard.alive[a] = False
        if self.hand.held == a:
            self.hand.held = -1
        self.attention.attended, self.attention.stale = -1, True

    def op_imagine_object(self, arg: int) -> None:
        b, (fx, fy) = self.blackboard, self.fovea.position
        if b.imagined_kind >= 0:
            raise Failure("an imagined object exists")
        footprint = imagined_pixels(arg, fx, fy, self.cfg)
        footprint = set(zip(footprint[0].tolist(), footprint[1].tolist()))
        for i in self.real_alive():
            if footprint & self.pixels(i):
                raise Failure("the imagined object would overlap an object")
        b.imagined_kind, b.imagined_position = arg, (fx, fy)

    def op_reset_imagination(self, arg: int) -> None:
        if self.blackboard.imagined_kind < 0:
            raise Failure("no imagined object")
        self.blackboard.imagined_kind = -1

    def op_loop_start(self, arg: int) -> None:
        self.refresh()
        ctl, a = self.control, self.attention
        ctl.in_loop = True
        ctl.loop_active = a.cursor < len(a.attended_list)
        ctl.body_ops, ctl.body_args, ctl.body_pc0 = [], [], ctl.pc

    def op_loop_end(self, arg: int) -> None:
        ctl, a = self.control, self.attention
        if not ctl.in_loop:
            raise Failure("loop_end without loop_start")
        if not REQUIRED_IN_LOOP <= {NAMES[op] for op in ctl.body_ops}:
            raise Failure("loop body lacks top_down_attend or next_object")
        ctl.in_loop = False
        if not ctl.loop_active:
            return
        iterations = 1  # the first ran eagerly
        while iterations < self.cfg.n_max and a.cursor < len(a.attended_list):
            for j, (op, arg) in enumerate(zip(ctl.body_ops, ctl.body_args)):
                pc = ctl.body_pc0 + j
                try:
                    self.execute(op, arg)
                except Failure as f:
                    self.fail(pc, f)
                if self.watch is not None:
                    self.watch(self, op, arg, pc)
                if ctl.failed:
                    return
            iterations += 1

    # ---- results ------------------------------------------------------------------------
    def output_scene(self) -> Scene:
        u = self.cfg.units
        objs = tuple(
            SceneObject(SHAPES[self.shapes[i]], COLORS[self.blackboard.color[i]], x / u, y / u, self.widths[i])
            for i in self.real_alive() for x, y in [self.centre(i)]
        )
        return Scene(objs, self.scene.pointer)


def run_reference(program: Program, scene: Scene, cfg: VCCConfig = DEFAULT_CONFIG) -> RefMachine:
    """Run a program on a scene; the machine holds status, failing index and output."""
    return RefMachine(scene, cfg).run(program)
