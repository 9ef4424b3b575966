"""A program's execution, instruction by instruction: what the machine held after each.

The reference interpreter calls a watcher after every instruction it executes, loop
iterations included (the body's instructions again, each time round), so a trace shows
what actually ran, in order, and where it failed. Each frame keeps a copy of the
machine; `vccjax.views.viewer` draws them.
"""

from __future__ import annotations

import dataclasses

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.instructions import NAMES, arg_domain
from vccjax.machine.program import Program
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene


@dataclasses.dataclass(frozen=True)
class Frame:
    step: int  # executed instructions before this one (0 for the first); -1 for the input
    pc: int  # the instruction's index in the program; -1 for the input
    instruction: str  # e.g. "fill_color(red)"; "input" before any
    machine: RefMachine  # a copy of the machine after the instruction
    iteration: int  # loop iteration this instruction ran in (0 outside a loop or in the first)

    @property
    def failed(self) -> bool:
        return self.machine.failed and self.machine.control.fail_index == self.pc


def instruction_text(op: int, arg: int) -> str:
    dom = arg_domain(NAMES[op])
    return NAMES[op] if not dom else f"{NAMES[op]}({dom[arg]})"


def trace(program: Program, scene: Scene, cfg: VCCConfig = DEFAULT_CONFIG) -> list[Frame]:
    """Run `program` on `scene`; one frame for the input and one per executed instruction."""
    machine = RefMachine(scene, cfg)
    frames = [Frame(-1, -1, "input", machine.clone(), 0)]
    seen: dict[int, int] = {}  # times each program index ran

    def watch(m: RefMachine, op: int, arg: int, pc: int) -> None:
        seen[pc] = seen.get(pc, 0) + 1
        snapshot = m.clone()
        snapshot.watch = None
        frames.append(Frame(len(frames) - 1, pc, instruction_text(op, arg), snapshot, seen[pc] - 1))

    machine.watch = watch
    machine.run(program)
    return frames
