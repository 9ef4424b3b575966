"""Example pairs for a concept: run its reference program on generated scenes (spec section 8).

A generated input is kept only if the program does not fail on it and changes it
(the output does not match the input within tau); outputs stay inside the workspace
by construction (motion keeps every object's box in it). The only per-concept scene
constraint is the pointer: present exactly when the program reads it. Everything
else a program needs (a shape present, free space for an imagined object) comes from
rejection, not from hand-written rules.

An example must also be *well posed*: its output may not hinge on a measurement finer
than an image can give. Each kept input is re-run with every object's centre and
width nudged by about the error of the image parser (`Jitter`); if any nudge changes
the outcome (the program fails, or the output differs beyond tau), the input is
dropped. Without this rule about one pair in twenty-five hinged on a grazing contact
(a slide that stops a sub-pixel short of a neighbour, a stack that just fits).
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


@dataclasses.dataclass(frozen=True)
class Jitter:
    """Nudges an example must survive: centres and widths moved by +-centre / +-width
    (each object, each coordinate, a random sign), `trials` times. The defaults cover
    the parser's 99.9th-percentile errors on varied-style images (0.003 and 0.008)."""

    centre: float = 0.003
    width: float = 0.008
    trials: int = 6
    small_trials: int = 6  # then nudges of random size within the same bounds: motion along a
    # path can flip on a small nudge that the extreme ones miss


TRAIN = ExampleSpec(10, (2, 6), (0.05, 0.15))
TEST = ExampleSpec(50, (2, 8), (0.04, 0.20))


def uses_pointer(program: Program) -> bool:
    return any(NAMES[op] in POINTER_OPS for op in program.ops)


class ExampleError(RuntimeError):
    """A concept whose examples could not be generated within the try budget."""


def _nudged(scene: Scene, jitter: Jitter, rng: np.random.Generator, extreme: bool = True) -> Scene:
    objs = []
    for o in scene.objects:
        sx, sy, sw = rng.choice((-1.0, 1.0), size=3) if extreme else rng.uniform(-1.0, 1.0, size=3)
        objs.append(dataclasses.replace(
            o, x=o.x + sx * jitter.centre, y=o.y + sy * jitter.centre,
            width=max(o.width + sw * jitter.width, 0.01),
        ))
    return Scene(tuple(objs), scene.pointer)


def is_well_posed(
    program: Program, scene: Scene, out: Scene, jitter: Jitter, rng: np.random.Generator,
    cfg: VCCConfig = DEFAULT_CONFIG,
) -> bool:
    """True if every nudge of the input still gives `out` (within tau)."""
    for t in range(jitter.trials + jitter.small_trials):
        nudged = _nudged(scene, jitter, rng, extreme=t < jitter.trials)
        try:
            nudged.validate(cfg)
        except SceneError:
            return False  # a nudge pushes an object out of the workspace or into another
        m = RefMachine(nudged, cfg, validate=False).run(program)
        if m.failed or not scenes_match(m.output_scene(), out, cfg.tau):
            return False
    return True


def make_pairs(
    program: Program, spec: ExampleSpec, rng: np.random.Generator,
    cfg: VCCConfig = DEFAULT_CONFIG, max_tries: int = 5000, jitter: Jitter | None = Jitter(),
) -> list[tuple[Scene, Scene]]:
    """`spec.count` well-posed (input, output) pairs on which the program runs and changes
    the scene. `jitter=None` skips the well-posedness rule."""
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
        if jitter is not None and not is_well_posed(program, scene, out, jitter, rng, cfg):
            continue
        pairs.append((scene, out))
    return pairs
