"""Packed states (one int32 row per state, what the search holds on the host) round-trip
exactly, batched or not, on states that real programs reach."""

from __future__ import annotations

import jax
import numpy as np

from vccjax import load_scene, random_scene, run
from vccjax.world.concepts import reference_program
from search.packing import blackboard_columns, pack_state, packed_field, unpack_blackboard, unpack_state
from vccjax.machine.state import init_state, stack


def _states():
    rng = np.random.default_rng(5)
    out = [init_state()]
    for name in ("swap_locations", "change_all_objs_color", "move_<COLOR>_objects_to_touch_imagined_horizontal_line_at_top_pointer"):
        program = reference_program(name)
        scene = random_scene(rng, 5, pointer=True)
        out.append(run(program, load_scene(scene)))
    return out


def _same(a, b) -> bool:
    return all(x.dtype == y.dtype and np.array_equal(x, y) for x, y in zip(jax.tree.leaves(a), jax.tree.leaves(b)))


def test_pack_round_trips_single_and_batched_states_on_device_and_host():
    states = _states()
    for s in states:
        p = pack_state(s)
        assert p.ndim == 1 and p.dtype == np.int32
        assert _same(unpack_state(p), s)
    batch = stack(states)  # (4, ...)
    packed = np.asarray(pack_state(batch))
    assert packed.shape[0] == len(states)
    host = unpack_state(packed)  # NumPy in, NumPy out
    assert _same(jax.tree.map(np.asarray, batch), host)
    assert np.array_equal(packed_field(packed, "hand.held"), np.asarray(batch.hand.held))
    assert np.array_equal(packed_field(packed, "control.failed"), np.asarray(batch.control.failed))
    # the blackboard leads a row: its leading columns unpack to the blackboard memory
    board = unpack_blackboard(packed[:, : blackboard_columns()])
    assert _same(board, host.blackboard)
    # a state that ran a program differs from the initial one, and packing keeps that
    assert not np.array_equal(packed[0], packed[1])
