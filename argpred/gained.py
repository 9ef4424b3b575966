"""`fill_color`'s arguments read from the pairs: the colours some object gains.

Only `fill_color` changes an object's colour (docs/vcc.md, section 3); moves keep
shape and colour, and `remove_from_imagine_buffer` only takes objects away. So where a
pair's output holds more objects of some (shape, colour) than its input, an object was
filled with that colour; where no pair shows such a rise, no `fill_color` in a program
that explains the pairs changes anything that stays. The network, which sees each grid
cell on its own, reads an object that moved onto a cell another object left as a
recolouring (docs/argpred.md, "Fill colours from the pairs"); this rule does not.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence

import numpy as np

from vccjax.machine.instructions import COLORS
from vccjax.machine.scene import Scene

FILL_MODES = ("gained", "predicted")  # gained: this rule; predicted: the network's fill_color outputs


def gained_colours(pairs: Sequence[tuple[Scene, Scene]]) -> list[str]:
    """The colours (in `COLORS` order) of which some pair's output holds more objects of
    one shape than its input."""
    gained: set[str] = set()
    for before, after in pairs:
        had = Counter((o.shape, o.color) for o in before.objects)
        has = Counter((o.shape, o.color) for o in after.objects)
        gained |= {colour for (shape, colour), n in has.items() if n > had[(shape, colour)]}
    return [c for c in COLORS if c in gained]


def fill_probabilities(pairs: Sequence[tuple[Scene, Scene]]) -> np.ndarray:
    """fill_color's probabilities over `COLORS` under the rule: 1 for a gained colour, 0 else."""
    gained = set(gained_colours(pairs))
    return np.array([1.0 if c in gained else 0.0 for c in COLORS])


def with_fill(probs: dict[str, np.ndarray], pairs: Sequence[tuple[Scene, Scene]], fill: str) -> dict[str, np.ndarray]:
    """The predictor's probabilities with fill_color's taken from `fill` ('gained' or 'predicted')."""
    if fill not in FILL_MODES:
        raise ValueError(f"--fill must be one of {', '.join(FILL_MODES)}, got {fill!r}")
    return {**probs, "fill_color": fill_probabilities(pairs)} if fill == "gained" else probs
