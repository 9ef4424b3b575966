"""Seeded random scenes (valid by construction) for tests, demos and benchmarks.

The tabletop-world dataset builds on this with per-concept rules.
"""

from __future__ import annotations

import cv2
import numpy as np

from vccjax.config import DEFAULT_CONFIG, VCCConfig
from vccjax.errors import SceneError
from vccjax.instructions import COLORS, SHAPES
from vccjax.geometry import object_pixels
from vccjax.scene import Scene, SceneObject, box_inside, to_units


def random_scene(
    rng: np.random.Generator,
    n_objects: int | tuple[int, int] = (2, 6),
    *,
    widths: tuple[float, float] = (0.05, 0.15),
    pointer: bool = False,
    cfg: VCCConfig = DEFAULT_CONFIG,
    max_tries: int = 200,
    gap: int = 2,
    pointer_clearance: int = 3,
) -> Scene:
    """A valid scene: objects drawn uniformly, placed by rejection.

    Generated inputs keep `gap` raster pixels between objects' masks (so that their
    drawn shapes never touch, as in the paper's figures, and an image parser can tell
    them apart), and the pointer `pointer_clearance` pixels away from every object.
    """
    if isinstance(n_objects, tuple):
        n = int(rng.integers(n_objects[0], n_objects[1] + 1))
    else:
        n = int(n_objects)
    if n > cfg.n_max:
        raise SceneError(f"asked for {n} objects; n_max is {cfg.n_max}")
    r = cfg.raster
    covered = np.zeros((r, r), bool)  # objects' masks
    blocked = np.zeros((r, r), bool)  # masks grown by `gap`
    objs: list[SceneObject] = []
    for _ in range(n):
        for _ in range(max_tries):
            w = float(rng.uniform(*widths))
            x, y = (float(v) for v in rng.uniform(w / 2, 1 - w / 2, size=2))
            cand = SceneObject(str(rng.choice(SHAPES)), str(rng.choice(COLORS)), x, y, w)
            if not box_inside(to_units(x, cfg), to_units(y, cfg), to_units(w, cfg), cfg):
                continue
            rows, cols = object_pixels(cand.shape, w, to_units(x, cfg), to_units(y, cfg), cfg)
            if blocked[rows, cols].any():
                continue
            objs.append(cand)
            covered[rows, cols] = True
            mask = np.zeros((r, r), np.uint8)
            mask[rows, cols] = 1
            blocked |= cv2.dilate(mask, np.ones((2 * gap + 1, 2 * gap + 1), np.uint8)) > 0
            break
        else:
            raise SceneError(f"could not place object {len(objs)} in {max_tries} tries")
    ptr = None
    if pointer:
        c = pointer_clearance
        for _ in range(max_tries):
            px, py = (float(v) for v in rng.uniform(0.05, 0.95, size=2))
            i, j = min(int(py * r), r - 1), min(int(px * r), r - 1)
            if not covered[max(i - c, 0) : i + c + 1, max(j - c, 0) : j + c + 1].any():
                ptr = (px, py)
                break
        else:
            raise SceneError(f"could not place the pointer clear of objects in {max_tries} tries")
    return Scene(tuple(objs), ptr)


def _bigram_table() -> np.ndarray:
    """Order-1 instruction transition counts of the reference programs (start = row N_OPS,
    end = column N_OPS), with a small floor so that every transition is possible."""
    from vccjax.concepts import all_concepts
    from vccjax.instructions import N_OPS

    table = np.full((N_OPS + 1, N_OPS + 1), 1e-3)
    for program in all_concepts().values():
        prev = N_OPS
        for op in program.ops:
            table[prev, op] += 1
            prev = op
        table[prev, N_OPS] += 1
    return table / table.sum(axis=1, keepdims=True)


_BIGRAMS: np.ndarray | None = None


def _next_op(rng: np.random.Generator, prev: int, noise: float) -> int:
    global _BIGRAMS
    from vccjax.instructions import N_OPS

    if _BIGRAMS is None:
        _BIGRAMS = _bigram_table()
    p = (1 - noise) * _BIGRAMS[prev] + noise / (N_OPS + 1)
    return int(rng.choice(N_OPS + 1, p=p))


def _random_arg(rng: np.random.Generator, op: int) -> int:
    from vccjax.instructions import NAMES, arg_domain

    dom = arg_domain(NAMES[op])
    return int(rng.integers(len(dom))) if dom else 0


def random_program(rng: np.random.Generator, max_len: int = 24, noise: float = 0.15):
    """A random (often failing) program: a walk on the reference programs' instruction
    bigrams mixed with uniform noise, random arguments, loops included."""
    from vccjax.instructions import N_OPS
    from vccjax.program import Program

    ops: list[int] = []
    prev = N_OPS
    while len(ops) < max_len:
        op = _next_op(rng, prev, noise)
        if op == N_OPS:
            if ops:
                break
            continue
        ops.append(op)
        prev = op
    return Program(tuple(ops), tuple(_random_arg(rng, o) for o in ops))


def random_deep_program(
    rng: np.random.Generator, scene: Scene, max_len: int = 24, noise: float = 0.2,
    p_fail: float = 0.03, cfg: VCCConfig = DEFAULT_CONFIG,
):
    """A random program that mostly runs on `scene`: each instruction is redrawn (a few
    times) when the reference machine says it fails, so programs reach deep states;
    with probability p_fail a failing instruction is kept and ends the program."""
    import copy

    from vccjax.instructions import N_OPS
    from vccjax.program import Program
    from vccjax.reference import RefMachine

    machine = RefMachine(scene, cfg, validate=False)
    ops: list[int] = []
    args: list[int] = []
    prev = N_OPS
    while len(ops) < max_len:
        for attempt in range(8):
            op = _next_op(rng, prev, noise)
            if op == N_OPS and rng.random() < 0.75:  # keep going: long programs reach deep states
                continue
            if op == N_OPS:
                break
            arg = _random_arg(rng, op)
            trial = copy.deepcopy(machine)
            trial.step(op, arg)
            if not trial.failed or attempt == 7 or rng.random() < p_fail:
                break
        else:
            op = N_OPS
        if op == N_OPS:
            if ops:
                break
            continue
        ops.append(op)
        args.append(arg)
        machine, prev = trial, op
        if machine.failed:
            break
    return Program(tuple(ops), tuple(args))
