"""Scenes of the tabletop world: objects, an optional pointer, validation, JSON and comparison."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.errors import SceneError, read_json
from vccjax.machine.geometry import object_pixels
from vccjax.machine.instructions import COLORS, SHAPES


@dataclasses.dataclass(frozen=True)
class SceneObject:
    shape: str
    color: str
    x: float
    y: float
    width: float

    def __post_init__(self) -> None:
        if self.shape not in SHAPES:
            raise SceneError(f"unknown shape {self.shape!r}; expected one of {list(SHAPES)}")
        if self.color not in COLORS:
            raise SceneError(f"unknown color {self.color!r}; expected one of {list(COLORS)}")
        for name in ("x", "y", "width"):
            if not _finite_number(getattr(self, name)):
                raise SceneError(f"object {name} must be a finite number, got {repr(getattr(self, name))[:40]}")

    def describe(self) -> str:
        return f"{self.color} {self.shape} at ({self.x:.3f}, {self.y:.3f}) width {self.width:.3f}"


def _finite_number(v) -> bool:
    """A real number (not a boolean) that a float holds finitely: JSON allows 400 digits."""
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
        return False
    try:
        return bool(np.isfinite(float(v)))
    except OverflowError:
        return False


@dataclasses.dataclass(frozen=True)
class Scene:
    """Objects on the unit square (x right, y down) and the teacher's pointer, if any."""

    objects: tuple[SceneObject, ...]
    pointer: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "objects", tuple(self.objects))
        if self.pointer is not None:
            object.__setattr__(self, "pointer", (float(self.pointer[0]), float(self.pointer[1])))

    # ---- validation -------------------------------------------------------------------
    def validate(self, cfg: VCCConfig = DEFAULT_CONFIG) -> Scene:
        """Raise SceneError unless every object is inside the workspace and none overlap."""
        if len(self.objects) > cfg.n_max:
            raise SceneError(f"scene has {len(self.objects)} objects; at most {cfg.n_max} fit (n_max)")
        for i, o in enumerate(self.objects):
            if not 0 < o.width <= cfg.max_width:
                raise SceneError(f"object {i} ({o.describe()}): width must be in (0, {cfg.max_width}]")
            if not box_inside(to_units(o.x, cfg), to_units(o.y, cfg), to_units(o.width, cfg), cfg):
                raise SceneError(f"object {i} ({o.describe()}) lies outside the workspace")
        if self.pointer is not None:
            px, py = self.pointer
            if not (0 <= px <= 1 and 0 <= py <= 1):
                raise SceneError(f"pointer {self.pointer} lies outside the workspace")
        occupied: dict[tuple[int, int], int] = {}
        for i, o in enumerate(self.objects):
            rows, cols = object_pixels(o.shape, o.width, to_units(o.x, cfg), to_units(o.y, cfg), cfg)
            for rc in zip(rows.tolist(), cols.tolist()):
                j = occupied.setdefault(rc, i)
                if j != i:
                    raise SceneError(
                        f"objects {j} ({self.objects[j].describe()}) and {i} ({o.describe()}) overlap"
                    )
        return self

    # ---- JSON -------------------------------------------------------------------------
    def to_dict(self) -> dict:
        d: dict = {"objects": [dataclasses.asdict(o) for o in self.objects]}
        if self.pointer is not None:
            d["pointer"] = list(self.pointer)
        return d

    @classmethod
    def from_dict(cls, d: dict, where: str = "scene") -> Scene:
        if not isinstance(d, dict) or not isinstance(d.get("objects"), list):
            raise SceneError(f"{where}: expected an object with an 'objects' list")
        objs = []
        for i, od in enumerate(d["objects"]):
            if not isinstance(od, dict):
                raise SceneError(f"{where}: object {i} is not a mapping")
            missing = {"shape", "color", "x", "y", "width"} - set(od)
            if missing:
                raise SceneError(f"{where}: object {i} lacks {sorted(missing)}")
            try:
                objs.append(SceneObject(od["shape"], od["color"], od["x"], od["y"], od["width"]))
            except SceneError as e:
                raise SceneError(f"{where}: object {i}: {e}") from None
        ptr = d.get("pointer")
        if ptr is not None and (not isinstance(ptr, (list, tuple)) or len(ptr) != 2
                                or not all(_finite_number(v) for v in ptr)):
            raise SceneError(f"{where}: pointer must be [x, y], two finite numbers")
        return cls(tuple(objs), None if ptr is None else (float(ptr[0]), float(ptr[1])))

    def save(self, path: str | Path) -> None:
        from vccjax import files

        files.write_json(path, self.to_dict())

    @classmethod
    def load(cls, path: str | Path) -> Scene:
        d = read_json(path, SceneError, "no such scene file", what="a JSON scene file")
        return cls.from_dict(d, where=str(path))


def to_units(v: float, cfg: VCCConfig) -> int:
    """A coordinate in [0, 1] as integer position units (round half to even)."""
    return int(np.rint(float(v) * cfg.units))


def box_inside(x: int, y: int, w: int, cfg: VCCConfig) -> bool:
    """Whether an object's w x w box (integer units, centre x, y) lies in the workspace.
    Doubled to stay in integers: 2x - w >= 0 and 2x + w <= 2U."""
    u2 = 2 * cfg.units
    return 2 * x - w >= 0 and 2 * x + w <= u2 and 2 * y - w >= 0 and 2 * y + w <= u2


def matching_size(a: Scene, b: Scene, tau: float) -> int:
    """How many objects of `a` can be paired one to one with objects of `b` of the same
    shape and color and a center within tau (a maximum bipartite matching)."""
    return _most_pairs([[oa.shape == ob.shape and oa.color == ob.color
                         and (oa.x - ob.x) ** 2 + (oa.y - ob.y) ** 2 <= tau * tau for ob in b.objects]
                        for oa in a.objects])


def aligned_size(a: Scene, b: Scene, tau: float) -> int:
    """As `matching_size`, with pairs whose centers need agree only in x or in y (within
    tau): objects already in their row or column. At least `matching_size`."""
    return _most_pairs([[oa.shape == ob.shape and oa.color == ob.color
                         and min(abs(oa.x - ob.x), abs(oa.y - ob.y)) <= tau for ob in b.objects]
                        for oa in a.objects])


def _most_pairs(ok: list[list[bool]]) -> int:
    """The size of a maximum matching of rows to columns where `ok` allows (augmenting paths)."""
    n_b = len(ok[0]) if ok else 0
    match_b = [-1] * n_b

    def augment(i: int, seen: list[bool]) -> bool:
        for j in range(n_b):
            if ok[i][j] and not seen[j]:
                seen[j] = True
                if match_b[j] < 0 or augment(match_b[j], seen):
                    match_b[j] = i
                    return True
        return False

    return sum(augment(i, [False] * n_b) for i in range(len(ok)))


def scenes_match(a: Scene, b: Scene, tau: float) -> bool:
    """docs/vcc.md section 7: same object count, matched one to one by shape, color and center within tau."""
    return len(a.objects) == len(b.objects) and matching_size(a, b, tau) == len(a.objects)


def scene_distance(a: Scene, b: Scene, tau: float) -> int:
    """Objects of either scene left unpaired by `matching_size`: 0 exactly when the
    scenes match; each object a program must still change, remove or add counts."""
    return len(a.objects) + len(b.objects) - 2 * matching_size(a, b, tau)
