"""Draw the README's worked example: before/after pictures of a concept that is not
among the 546 ("recolour the bottom object blue"), as a user would draw them.

The two first pairs are drawn on purpose with the bottom object also the left-most one,
as a user might without noticing: two pairs then leave the concept ambiguous, and
`vcc learn` asks back. Run from the repository root:

    python examples/teach/draw_pairs.py
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from vccjax.machine.program import parse
from vccjax.machine.reference import RefMachine
from vccjax.vision.render import render
from vccjax.world.scenes import random_scene

CONCEPT = parse("scene_parse; fixate(bottom); top_down_attend; fill_color(blue)")  # only the drawer knows it
HERE = Path(__file__).parent


def draw(path: Path, scene) -> None:
    cv2.imwrite(str(path), cv2.cvtColor(render(scene, 256), cv2.COLOR_RGB2BGR))


def main() -> None:
    folder = HERE / "bottom_to_blue"
    folder.mkdir(exist_ok=True)
    k, seed = 0, 0
    while k < 2:
        scene = random_scene(np.random.default_rng(seed), (3, 4), shapes=("circle", "square", "triangle"),
                             colors=("red", "green", "yellow"))
        seed += 1
        bottom = max(scene.objects, key=lambda o: o.y)
        if bottom is not min(scene.objects, key=lambda o: o.x):
            continue  # keep only tables whose bottom object is also the left-most
        out = RefMachine(scene).run(CONCEPT)
        if out.failed:
            continue  # a failed run leaves a half-made table, no output of the concept
        draw(folder / f"{k}_in.png", scene)
        draw(folder / f"{k}_out.png", out.output_scene())
        k += 1
    print(f"wrote {folder}")


if __name__ == "__main__":
    main()
