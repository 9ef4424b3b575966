"""Contact bitmaps of vccjax.machine.motion against the objects' pixel masks, batched as the search runs them."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from vccjax.machine import motion
from vccjax.machine import step as emulator
from vccjax.machine.config import DEFAULT_CONFIG as CFG
from vccjax.world.programs import random_deep_program
from vccjax.world.scenes import random_scene
from vccjax.machine.state import load_scene, object_masks, stack


def _unpack(bits: np.ndarray) -> np.ndarray:
    """(..., R, W) uint32 bit lines as (..., R, R) bools."""
    b = (bits[..., None] >> np.arange(32, dtype=np.uint32)) & 1
    return b.reshape(bits.shape[:-1] + (-1,))[..., : CFG.raster].astype(bool)


def test_occupancy_is_every_other_alive_mask_in_both_orientations():
    """The block-wise bitmap (one scatter block per object) is the union of the other
    alive objects' masks, per row (axis 0) and per column (axis 1), after motion too."""
    rng = np.random.default_rng(5)
    scenes = [random_scene(rng, (1, 8), pointer=True) for _ in range(48)]
    progs = [random_deep_program(rng, sc, max_len=20, p_fail=0.0) for sc in scenes]
    consts = stack([load_scene(sc) for sc in scenes])
    arrays = [p.arrays(32) for p in progs]
    states = emulator.run_programs(CFG, consts, *(jnp.asarray(np.stack([a[k] for a in arrays])) for k in (0, 1)))
    excl = jnp.asarray(rng.integers(-1, CFG.n_max, len(scenes)), jnp.int32)

    def occ(c, s, e):
        return tuple(motion.occupancy(c, s, CFG, e, axis, imagined=False) for axis in (0, 1))

    rows, cols = jax.device_get(jax.jit(jax.vmap(occ))(consts, states, excl))
    masks = np.asarray(jax.vmap(lambda c, s: object_masks(c, s, CFG))(consts, states))
    others = np.arange(CFG.n_max)[None, :] != np.asarray(excl)[:, None]
    want = (masks & others[:, :, None, None]).any(axis=1)
    assert masks.any()
    assert np.array_equal(_unpack(rows), want)
    assert np.array_equal(_unpack(cols), np.swapaxes(want, 1, 2))
