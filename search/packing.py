"""Packed states: one int32 row per machine state, for a search that holds many.

A search keeps every open prefix's (E,) states on the host; one array per batch instead
of one per field keeps its copies and transfers cheap. A row holds the state's leaves
in field order, memory by memory ("blackboard.alive", ..., "control.body_pc0"); the
blackboard comes first, so judging outputs moves a small leading slice of each state.
"""

from __future__ import annotations

import dataclasses
import functools
import typing

import jax
import jax.numpy as jnp
import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.state import Blackboard, VCCState, init_state

MEMORY_CLASSES = typing.get_type_hints(VCCState)  # {"blackboard": Blackboard, ...}, in field order


@functools.lru_cache(maxsize=None)
def _layout(cfg: VCCConfig) -> tuple[tuple[str, tuple, bool, int, int], ...]:
    """(path, shape, is_bool, start, stop) of each VCCState leaf ("hand.held") in a packed row."""
    s, out, pos = init_state(cfg), [], 0
    for m in dataclasses.fields(VCCState):
        memory = getattr(s, m.name)
        for f in dataclasses.fields(memory):
            a = getattr(memory, f.name)
            size = int(np.prod(a.shape, dtype=int))
            out.append((f"{m.name}.{f.name}", tuple(a.shape), a.dtype == jnp.bool_, pos, pos + size))
            pos += size
    return tuple(out)


def _leaf(s: VCCState, path: str):
    memory, field = path.split(".")
    return getattr(getattr(s, memory), field)


def pack_state(s: VCCState, cfg: VCCConfig = DEFAULT_CONFIG) -> jax.Array:
    """A (batched) state as one int32 array (..., P). A search holds many states on the
    host; one array per batch instead of one per field keeps its copies and transfers cheap."""
    failed = s.control.failed
    batch = failed.shape
    parts = [_leaf(s, path).reshape(batch + (stop - start,)) for path, _, _, start, stop in _layout(cfg)]
    xp = np if isinstance(failed, np.ndarray) else jnp
    return xp.concatenate([p.astype(xp.int32) for p in parts], axis=-1)


def _field(p, shape: tuple, is_bool: bool, start: int, stop: int):
    a = p[..., start:stop].reshape(p.shape[:-1] + shape)
    return a.astype(bool) if is_bool else a


def _memory(p, name: str, cfg: VCCConfig):
    """Memory `name` ("hand") of packed rows."""
    leaves = {path.split(".")[1]: _field(p, *where) for path, *where in _layout(cfg) if path.startswith(name + ".")}
    return MEMORY_CLASSES[name](**leaves)


def unpack_state(p, cfg: VCCConfig = DEFAULT_CONFIG) -> VCCState:
    """`pack_state` undone; on a NumPy array the int fields are views, not copies."""
    return VCCState(**{name: _memory(p, name, cfg) for name in MEMORY_CLASSES})


def packed_field(p: np.ndarray, path: str, cfg: VCCConfig = DEFAULT_CONFIG) -> np.ndarray:
    """One leaf of packed states ("hand.held", "control.failed"), without unpacking the rest."""
    for leaf, *where in _layout(cfg):
        if leaf == path:
            return _field(p, *where)
    raise KeyError(path)


@functools.lru_cache(maxsize=None)
def blackboard_columns(cfg: VCCConfig = DEFAULT_CONFIG) -> int:
    """How many leading columns of a packed row hold the blackboard (the layout puts its
    leaves first, so judging outputs moves a small slice of each state, not all of it)."""
    return max(stop for path, _, _, _, stop in _layout(cfg) if path.startswith("blackboard."))


def unpack_blackboard(p, cfg: VCCConfig = DEFAULT_CONFIG) -> Blackboard:
    """The blackboard memory of packed rows, full or cut to `blackboard_columns`."""
    return _memory(p, "blackboard", cfg)
