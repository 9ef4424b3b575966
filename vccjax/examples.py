"""Example pairs for a concept: run its reference program on generated scenes (spec section 8).

A generated input is kept only if the program does not fail on it and changes it
(the output does not match the input within tau); outputs stay inside the workspace
by construction (motion keeps every object's box in it). The only per-concept scene
constraint is the pointer: present exactly when the program reads it. Everything
else a program needs (a shape present, free space for an imagined object) comes from
rejection, not from hand-written rules.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from vccjax.config import DEFAULT_CONFIG, VCCConfig
from vccjax.errors import SceneError
from vccjax.generate import random_scene
from vccjax.instructions import NAMES
from vccjax.program import Program
from vccjax.reference import RefMachine
from vccjax.scene import Scene, scenes_match

POINTER_OPS = frozenset({"fixate_pointer", "move_hand_to_pointer", "attend_pointer"})


@dataclasses.dataclass(frozen=True)
class ExampleSpec:
    """How a split's input scenes are drawn."""

    count: int
    objects: tuple[int, int]
    widths: tuple[float, float]


TRAIN = ExampleSpec(10, (2, 6), (0.05, 0.15))
TEST = ExampleSpec(50, (2, 8), (0.04, 0.20))


def uses_pointer(program: Program) -> bool:
    return any(NAMES[op] in POINTER_OPS for op in program.ops)


class ExampleError(RuntimeError):
    """A concept whose examples could not be generated within the try budget."""


def make_pairs(
    program: Program, spec: ExampleSpec, rng: np.random.Generator,
    cfg: VCCConfig = DEFAULT_CONFIG, max_tries: int = 5000,
) -> list[tuple[Scene, Scene]]:
    """`spec.count` (input, output) pairs on which the program runs and changes the scene."""
    pointer = uses_pointer(program)
    pairs: list[tuple[Scene, Scene]] = []
    tries = 0
    while len(pairs) < spec.count:
        tries += 1
        if tries > max_tries:
            raise ExampleError(
                f"only {len(pairs)} of {spec.count} pairs after {max_tries} scenes "
                f"({spec.objects[0]}-{spec.objects[1]} objects)"
            )
        try:
            scene = random_scene(rng, spec.objects, widths=spec.widths, pointer=pointer, cfg=cfg)
        except SceneError:
            continue  # too crowded to place; draw again
        m = RefMachine(scene, cfg, validate=False).run(program)
        if m.failed:
            continue
        out = m.output_scene()
        if scenes_match(out, scene, cfg.tau):
            continue
        pairs.append((scene, out))
    return pairs
