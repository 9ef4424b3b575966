"""The camera's parse against the scene that really stands on the table.

The arm acts on what the camera parsed; a parse that drops an object, merges two, or
reads a colour wrong can still be carried out "correctly" against itself. So each true
object is matched to at most one parsed object (nearest centres first, within
`REACH`), and the parse is exact when every true object has a match of the same shape
and colour whose centre is within `CENTRE_TOLERANCE`, and nothing else was seen.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from robot.world import WORKSPACE_SIDE
from vccjax.machine.scene import Scene

CENTRE_TOLERANCE = 0.02  # workspace units (8 mm): a parsed centre further off is a parse error
REACH = 0.10  # workspace units: a parsed object further than this from a true one is not it


@dataclasses.dataclass(frozen=True)
class ParseCheck:
    """How the parse compares with the truth (what a scenario record keeps)."""

    objects: int  # true objects on the workspace
    seen: int  # parsed objects
    found: int  # true objects matched to a parsed one
    shape_right: int  # of the matched, with the true shape
    color_right: int  # of the matched, with the true colour
    exact_objects: int  # of the matched, shape, colour and centre all right
    centre_error_m: float  # largest centre error among the matched (metres; 0 if none)
    pointer_right: bool  # a pointer seen where there is one (within the tolerance), none where there is none
    match: tuple[int, ...]  # per parsed object, the true object it is (-1: none)

    @property
    def exact(self) -> bool:
        return (self.found == self.objects == self.seen and self.shape_right == self.color_right == self.found
                and self.centre_error_m <= CENTRE_TOLERANCE * WORKSPACE_SIDE and self.pointer_right)

    def problem(self) -> str | None:
        """One line naming what the parse got wrong, or None when it is exact."""
        if self.exact:
            return None
        if self.found < self.objects:
            return f"{self.objects - self.found} of {self.objects} objects not seen"
        if self.seen > self.found:
            return f"{self.seen - self.found} object(s) seen that are not there"
        if self.shape_right < self.found:
            return f"{self.found - self.shape_right} shape(s) read wrong"
        if self.color_right < self.found:
            return f"{self.found - self.color_right} colour(s) read wrong"
        if not self.pointer_right:
            return "the pointer read wrong"
        return f"a centre {self.centre_error_m * 100:.1f} cm off"

    def record(self) -> dict:
        return {k: v for k, v in dataclasses.asdict(self).items() if k != "match"} | {"exact": self.exact}


def check_parse(truth: Scene, parsed: Scene) -> ParseCheck:
    """Match parsed objects to true ones (closest pairs first, one to one, within REACH)."""
    t = np.array([(o.x, o.y) for o in truth.objects], float).reshape(-1, 2)
    p = np.array([(o.x, o.y) for o in parsed.objects], float).reshape(-1, 2)
    dist = np.linalg.norm(p[:, None, :] - t[None, :, :], axis=-1) if len(p) and len(t) else np.zeros((len(p), len(t)))
    match = [-1] * len(p)
    used: set[int] = set()
    for flat in np.argsort(dist, axis=None, kind="stable"):
        i, j = divmod(int(flat), len(t))
        if dist[i, j] > REACH:
            break
        if match[i] < 0 and j not in used:
            match[i] = j
            used.add(j)
    pairs = [(parsed.objects[i], truth.objects[j], dist[i, j]) for i, j in enumerate(match) if j >= 0]
    if truth.pointer is None or parsed.pointer is None:
        pointer = truth.pointer is None and parsed.pointer is None
    else:
        pointer = bool(np.hypot(*np.subtract(truth.pointer, parsed.pointer)) <= CENTRE_TOLERANCE)
    exact = sum(bool(a.shape == b.shape and a.color == b.color and d <= CENTRE_TOLERANCE) for a, b, d in pairs)
    return ParseCheck(len(truth.objects), len(parsed.objects), len(pairs),
                      sum(a.shape == b.shape for a, b, _ in pairs), sum(a.color == b.color for a, b, _ in pairs), exact,
                      float(max((d for _, _, d in pairs), default=0.0) * WORKSPACE_SIDE), pointer, tuple(match))
