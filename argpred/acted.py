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
loses the filter.

The pairs also point values in (`--filters acted+raised`, the default): where, over all
pairs, the objects changed are of at most two colours (shapes), a filter on those kinds
explains the pairs, and such a value the network gives at least `SUPPORT` is raised to
the threshold ("all yellow left AND all green right" whose pairs the network reads as
yellow alone); and a value beside which the moved objects end, in nearly every pair, is a
landmark the program attends ("move the star to touch the circle"), raised too. The
network alone misses these where the value's objects are few or never change. `--filters
acted` only rules values out, `--filters network` takes the network's alone.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence

import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.instructions import COLORS, SHAPES
from vccjax.machine.scene import Scene, SceneObject

# acted+raised: values ruled out and pointed in; acted: ruled out only; network: the network alone
FILTER_MODES = ("acted+raised", "acted", "network")
SPAN = 3  # kinds of objects changed in one pair that no one or two filters of that attribute explain
SUPPORT = 0.2  # the network's least probability for a value of the changed kinds to be raised
LANDMARK_SHARE = 0.9  # share of the pairs with moved objects in which they end beside the value
LANDMARK_PAIRS = 5  # fewer pairs with moved objects than this point to no landmark (chance)
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


def changed_kinds(pairs: Sequence[tuple[Scene, Scene]], attr: str, tau: float = DEFAULT_CONFIG.tau) -> set[str]:
    """The values of `attr` ('shape' or 'color') of the objects any pair changes."""
    return {getattr(o, attr) for a, b in pairs for o in a.objects if not stays(o, b, tau)}


def landmarks(pairs: Sequence[tuple[Scene, Scene]], attr: str, tau: float = DEFAULT_CONFIG.tau) -> set[str]:
    """The values of `attr` of the object nearest to where every moved object ends (among
    the objects left in place), in at least `LANDMARK_SHARE` of the pairs that move any;
    none with fewer than `LANDMARK_PAIRS` such pairs."""
    beside: list[set[str]] = []
    for a, b in pairs:
        left = [stays(o, a, tau) for o in b.objects]  # each output object: at its input place
        moved = [o for o, k in zip(b.objects, left) if not k]
        still = [o for o, k in zip(b.objects, left) if k]
        if not moved:
            continue
        near = [getattr(min(still, key=lambda p: math.hypot(p.x - o.x, p.y - o.y)), attr)
                for o in moved] if still else []
        beside.append(set(near) if len(set(near)) == 1 else set())
    if len(beside) < LANDMARK_PAIRS:
        return set()
    counts = Counter(v for values in beside for v in values)
    return {v for v, k in counts.items() if k >= LANDMARK_SHARE * len(beside)}


def raised_values(probs: dict[str, np.ndarray], pairs: Sequence[tuple[Scene, Scene]],
                  tau: float = DEFAULT_CONFIG.tau) -> dict[str, set[str]]:
    """Per filter instruction, the values the pairs point in (see the module's docstring)."""
    out: dict[str, set[str]] = {}
    for name, (attr, domain) in _FILTERS.items():
        kinds = changed_kinds(pairs, attr, tau)
        p = dict(zip(domain, np.asarray(probs.get(name, np.zeros(len(domain))), np.float64)))
        confined = {v for v in kinds if p.get(v, 0.0) >= SUPPORT} if len(kinds) < SPAN else set()
        out[name] = confined | landmarks(pairs, attr, tau)
    return out


def check_filters(filters: str) -> None:
    """One line naming a filters mode that is not one (settings read from a file, or code)."""
    if filters not in FILTER_MODES:
        raise ValueError(f"--filters must be one of {', '.join(FILTER_MODES)}, got {filters!r}")


def with_filters(probs: dict[str, np.ndarray], pairs: Sequence[tuple[Scene, Scene]], filters: str,
                 tau: float = DEFAULT_CONFIG.tau, threshold: float = 0.55) -> dict[str, np.ndarray]:
    """The predictor's probabilities with the filter values the pairs rule out set to 0
    (`filters` 'acted'), those they point in then raised to at least `threshold`
    (the search's, `argpred.predict.THRESHOLD` by default; 'acted+raised'), or unchanged
    ('network')."""
    check_filters(filters)
    if filters == "network":
        return probs
    out = dict(probs)
    for name, values in allowed_values(pairs, tau).items():
        if values is not None and name in out:
            domain = _FILTERS[name][1]
            out[name] = np.where([v in values for v in domain], np.asarray(out[name], np.float64), 0.0)
    if filters == "acted+raised":
        for name, values in raised_values(out, pairs, tau).items():
            if values and name in out:
                domain = _FILTERS[name][1]
                p = np.asarray(out[name], np.float64)
                out[name] = np.where([v in values for v in domain], np.maximum(p, threshold), p)
    return out
