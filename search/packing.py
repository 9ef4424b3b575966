"""Packed states: one int32 row per machine state, for a search that holds many.

A search keeps every open prefix's (E,) states on the host; one array per batch instead
of one per field keeps its copies and transfers cheap. The blackboard fields come first
in a row, so judging outputs moves a small slice of each state, not all of it.
"""

from __future__ import annotations

import dataclasses
import functools

import jax
import jax.numpy as jnp
import numpy as np
from flax import struct

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.state import VCCState, init_state


@functools.lru_cache(maxsize=None)
def _layout(cfg: VCCConfig) -> tuple[tuple[str, tuple, bool, int, int], ...]:
    """(field, shape, is_bool, start, stop) of each VCCState field in a packed row."""
    s, out, pos = init_state(cfg), [], 0
    for f in dataclasses.fields(VCCState):
        a = getattr(s, f.name)
        size = int(np.prod(a.shape, dtype=int))
        out.append((f.name, tuple(a.shape), a.dtype == jnp.bool_, pos, pos + size))
        pos += size
    return tuple(out)


def pack_state(s: VCCState, cfg: VCCConfig = DEFAULT_CONFIG) -> jax.Array:
    """A (batched) state as one int32 array (..., P). A search holds many states on the
    host; one array per batch instead of one per field keeps its copies and transfers cheap."""
    batch = s.failed.shape
    parts = [getattr(s, name).reshape(batch + (stop - start,)) for name, _, _, start, stop in _layout(cfg)]
    xp = np if isinstance(s.failed, np.ndarray) else jnp
    return xp.concatenate([p.astype(xp.int32) for p in parts], axis=-1)


def _field(p, shape: tuple, is_bool: bool, start: int, stop: int):
    a = p[..., start:stop].reshape(p.shape[:-1] + shape)
    return a.astype(bool) if is_bool else a


def unpack_state(p, cfg: VCCConfig = DEFAULT_CONFIG) -> VCCState:
    """`pack_state` undone; on a NumPy array the int fields are views, not copies."""
    return VCCState(**{name: _field(p, *where) for name, *where in _layout(cfg)})


def packed_field(p: np.ndarray, name: str, cfg: VCCConfig = DEFAULT_CONFIG) -> np.ndarray:
    """One field of packed states, without unpacking the rest."""
    for field, *where in _layout(cfg):
        if field == name:
            return _field(p, *where)
    raise KeyError(name)


@struct.dataclass
class Blackboard:
    """What output matching reads of a state: the objects' presence, colours and offsets."""

    alive: jax.Array
    color: jax.Array
    offset: jax.Array


BLACKBOARD = tuple(f.name for f in dataclasses.fields(Blackboard))


@functools.lru_cache(maxsize=None)
def blackboard_columns(cfg: VCCConfig = DEFAULT_CONFIG) -> int:
    """How many leading columns of a packed row hold the blackboard (the layout puts those
    fields first, so judging outputs moves a small slice of each state, not all of it)."""
    return max(stop for name, _, _, _, stop in _layout(cfg) if name in BLACKBOARD)


def unpack_blackboard(p, cfg: VCCConfig = DEFAULT_CONFIG) -> Blackboard:
    """The blackboard of packed rows, full or cut to `blackboard_columns`."""
    return Blackboard(**{name: _field(p, *where) for name, *where in _layout(cfg) if name in BLACKBOARD})
