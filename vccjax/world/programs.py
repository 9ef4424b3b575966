"""Seeded random programs for testing the machines: walks on the reference programs'
instruction bigrams, mixed with uniform noise, loops included. `random_deep_program`
keeps redrawing failing instructions so that programs reach deep states."""

from __future__ import annotations

import copy

import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.instructions import N_OPS, NAMES, arg_domain
from vccjax.machine.program import Program
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene
from vccjax.world.concepts import all_concepts


def _bigram_table() -> np.ndarray:
    """Order-1 instruction transition counts of the reference programs (start = row N_OPS,
    end = column N_OPS), with a small floor so that every transition is possible."""
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
    if _BIGRAMS is None:
        _BIGRAMS = _bigram_table()
    p = (1 - noise) * _BIGRAMS[prev] + noise / (N_OPS + 1)
    return int(rng.choice(N_OPS + 1, p=p))


def _random_arg(rng: np.random.Generator, op: int) -> int:
    dom = arg_domain(NAMES[op])
    return int(rng.integers(len(dom))) if dom else 0


def random_program(rng: np.random.Generator, max_len: int = 24, noise: float = 0.15):
    """A random (often failing) program: a walk on the reference programs' instruction
    bigrams mixed with uniform noise, random arguments, loops included."""
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
