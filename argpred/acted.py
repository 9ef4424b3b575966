"""Attention filters checked against the pairs: which shape and colour filter values the
objects a concept acts on leave possible.

A shape (colour) filter makes `top_down_attend` attend objects of that one shape
(colour) only (docs/vcc.md, sections 3 and 11), so a program that sets a shape filter
once or twice changes, in any one pair, objects of at most two shapes through it. Where
the objects a pair changes (moved, recoloured or removed: no object of the same shape and
colour left at their place) are of three or more shapes, some part of the program
changed several kinds with no shape filter (a loop over every object, the pointer, the
hand's moves). We take that part to be what the concept does; a shape filter can then
only have picked an object left as it was, a landmark ("move every object to the red
one"), so the values kept are those of which some object stays put in every pair. The
network cannot see this: it sees each grid cell on its own, and reads "a diamond
changed" as "a diamond filter" where every object changed (docs/argpred.md, "Filters
the objects acted on rule out").

Unlike `argpred.gained`, this is not exact: a concept that acts on some objects through
a filter and on several kinds with none ("the squares left, then every object up")
loses the filter. Searches take it by default (`--filters acted`); `--filters network`
searches with the network's filters alone.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.instructions import COLORS, SHAPES
from vccjax.machine.scene import Scene, SceneObject

FILTER_MODES = ("acted", "network")  # acted: this rule on top of the network; network: the network alone
SPAN = 3  # kinds of objects changed in one pair that no one or two filters of that attribute explain
_FILTERS = {"set_shape_attn": ("shape", SHAPES), "set_color_attn": ("color", COLORS)}


def stays(o: SceneObject, after: Scene, tau: float) -> bool:
    """Whether an object of the same shape and colour sits at `o`'s place in `after`."""
    return any(p.shape == o.shape and p.color == o.color and abs(p.x - o.x) <= tau and abs(p.y - o.y) <= tau
               for p in after.objects)


def allowed_values(pairs: Sequence[tuple[Scene, Scene]], tau: float = DEFAULT_CONFIG.tau) -> dict[str, set[str] | None]:
    """Per filter instruction, the values the pairs leave possible (None: any value)."""
    out: dict[str, set[str] | None] = {}
    for name, (attr, _) in _FILTERS.items():
        changed = [{getattr(o, attr) for o in a.objects if not stays(o, b, tau)} for a, b in pairs]
        if not pairs or max(len(c) for c in changed) < SPAN:
            out[name] = None
            continue
        kept = [{getattr(o, attr) for o in a.objects if stays(o, b, tau)} for a, b in pairs]
        out[name] = set.intersection(*kept)
    return out


def check_filters(filters: str) -> None:
    """One line naming a filters mode that is not one (settings read from a file, or code)."""
    if filters not in FILTER_MODES:
        raise ValueError(f"--filters must be one of {', '.join(FILTER_MODES)}, got {filters!r}")


def with_filters(probs: dict[str, np.ndarray], pairs: Sequence[tuple[Scene, Scene]], filters: str,
                 tau: float = DEFAULT_CONFIG.tau) -> dict[str, np.ndarray]:
    """The predictor's probabilities with the filter values the pairs rule out set to 0
    (`filters` 'acted'), or unchanged ('network')."""
    check_filters(filters)
    if filters == "network":
        return probs
    out = dict(probs)
    for name, values in allowed_values(pairs, tau).items():
        if values is not None and name in out:
            domain = _FILTERS[name][1]
            out[name] = np.where([v in values for v in domain], np.asarray(out[name], np.float64), 0.0)
    return out
