"""Draw the zero-shot demonstration's pairs: before/after pictures of a concept that is
not among the 546 ("slide the left-most object to the right, as far as it goes"), as a
user would draw them, for `vcc learn`; the arm then carries the learned concept out on
tables it never saw (`vcc robot run --concept NAME`).

The tables are chosen so that the pairs are not ambiguous: the left-most object is not
also the top, bottom or central one, its colour is not one only it has, and at least
one other object has its shape. Run from the repository root:

    python examples/zero_shot/draw_pairs.py
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from vccjax.machine.program import parse
from vccjax.machine.reference import RefMachine
from vccjax.vision.render import render
from vccjax.world.scenes import random_scene

CONCEPT = parse("scene_parse; fixate(left); top_down_attend; move_hand_to_attended_object; grab_object; "
                "move_hand_right; release_object")  # only the drawer knows it
PAIRS = 4
HERE = Path(__file__).parent


def telling(scene) -> bool:
    """Whether this table shows the concept unambiguously (module docstring)."""
    left = min(scene.objects, key=lambda o: o.x)
    others = [o for o in scene.objects if o is not left]
    centre = min(scene.objects, key=lambda o: (o.x - 0.5) ** 2 + (o.y - 0.5) ** 2)
    extreme = {id(max(scene.objects, key=lambda o: o.y)), id(min(scene.objects, key=lambda o: o.y)), id(centre)}
    return (id(left) not in extreme and any(o.color == left.color for o in others)
            and any(o.shape == left.shape for o in others))


def main() -> None:
    folder = HERE / "left_most_right"
    folder.mkdir(exist_ok=True)
    k, seed = 0, 0
    while k < PAIRS:
        rng = np.random.default_rng([seed, 5])
        seed += 1
        scene = random_scene(rng, (3, 4), shapes=("circle", "square", "diamond"), colors=("red", "green", "blue"))
        if not telling(scene):
            continue
        out = RefMachine(scene).run(CONCEPT)
        if out.failed:
            continue
        for name, s in ((f"{k}_in.png", scene), (f"{k}_out.png", out.output_scene())):
            cv2.imwrite(str(folder / name), cv2.cvtColor(render(s, 256), cv2.COLOR_RGB2BGR))
        k += 1
    print(f"wrote {folder}")


if __name__ == "__main__":
    main()
