"""Shared helpers: run a program on both machines and summarise their states alike."""

from __future__ import annotations

import os

os.environ.setdefault("XLA_FLAGS", "--xla_force_host_platform_device_count=1")

import jax.numpy as jnp
import numpy as np
import pytest

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.step import pad_length, run_program
from vccjax.machine.program import Program, parse
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, SceneObject
from vccjax.machine.state import VCCState, load_scene


def obj(shape: str, color: str, x: float, y: float, w: float = 0.1) -> SceneObject:
    return SceneObject(shape, color, x, y, w)


def scene(*objects: SceneObject, pointer=None) -> Scene:
    return Scene(tuple(objects), pointer)


def summary_ref(m: RefMachine) -> dict:
    """The machine state both implementations must agree on."""
    d = {"failed": m.failed, "fail_index": -1 if m.fail_index is None else m.fail_index}
    if m.failed:
        return d
    d.update(
        objects=[(o.shape, o.color, o.x, o.y) if o.alive else None for o in m.objects],
        fovea=tuple(m.fovea), history=[tuple(p) for p in m.history], h=m.h,
        hand=tuple(m.hand), held=-1 if m.held is None else m.held,
        attended=-1 if m.attended is None else m.attended,
        shape_filter=-1 if m.shape_filter is None else m.shape_filter,
        color_filter=-1 if m.color_filter is None else m.color_filter,
        cursor=m.k, attended_list=None if m.stale else list(m.attended_list),
        imagined=None if m.imagined is None else tuple(m.imagined),
    )
    return d


def summary_jax(s: VCCState, c, cfg: VCCConfig = DEFAULT_CONFIG) -> dict:
    failed = bool(s.failed)
    d = {"failed": failed, "fail_index": int(s.fail_index)}
    if failed:
        return d
    n = int(c.n)
    cen = np.asarray(c.base) + np.asarray(s.offset) * cfg.sub
    alive, shape, color = np.asarray(s.alive), np.asarray(c.shape), np.asarray(s.color)
    hl = int(s.hist_len)
    d.update(
        objects=[(int(shape[i]), int(color[i]), int(cen[i, 0]), int(cen[i, 1])) if alive[i] else None
                 for i in range(n)] if bool(s.parsed) else [],
        fovea=tuple(int(v) for v in s.fovea),
        history=[tuple(int(v) for v in p) for p in np.asarray(s.hist)[:hl]], h=int(s.hist_idx),
        hand=tuple(int(v) for v in s.hand), held=int(s.held), attended=int(s.attended),
        shape_filter=int(s.shape_filter), color_filter=int(s.color_filter), cursor=int(s.cursor),
        attended_list=None if bool(s.stale) else [int(v) for v in np.asarray(s.attn)[: int(s.attn_len)]],
        imagined=None if int(s.imag_kind) < 0 else (int(s.imag_kind), *(int(v) for v in s.imag_pos)),
    )
    return d


def run_both(program: Program | str, sc: Scene, cfg: VCCConfig = DEFAULT_CONFIG):
    """Run on the reference and on the jitted JAX emulator; assert they agree; return both."""
    if isinstance(program, str):
        program = parse(program, check_loops=False)
    ref = RefMachine(sc, cfg).run(program)
    c = load_scene(sc, cfg)
    ops, args, _ = program.arrays(pad_length(len(program)))
    st = run_program(cfg, c, jnp.asarray(ops), jnp.asarray(args))
    a, b = summary_ref(ref), summary_jax(st, c, cfg)
    assert a == b, f"reference and JAX disagree on {program}:\nref {a}\njax {b}"
    return ref, st


@pytest.fixture
def both():
    return run_both
