"""docs/vcc.md section 7 on device: does a state's blackboard match an example's output?

`scenes_match` (host) finds a one-to-one matching by shape, colour and centre within
tau. On device a full matching is not needed: when every object has exactly one
candidate partner on each side the matching is that one; when some object has none
the answer is no; only when an object has two candidates (two same-looking objects
within tau of each other, which generated scenes almost never hold) is the answer
left to the host. So the verdict is YES, NO or ASK.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
from flax import struct

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.instructions import COLORS, SHAPES
from vccjax.machine.scene import Scene
from vccjax.machine.state import Blackboard, SceneConst, centres

NO, YES, ASK = 0, 1, 2


@struct.dataclass
class Target:
    """An example's output scene on fixed arrays (position units)."""

    alive: jax.Array  # (N,) bool
    shape: jax.Array  # (N,)
    color: jax.Array  # (N,)
    pos: jax.Array  # (N, 2) float32 position units (a loaded scene need not sit on the grid)


def load_target(scene: Scene, cfg: VCCConfig = DEFAULT_CONFIG) -> Target:
    n = cfg.n_max
    if len(scene.objects) > n:
        raise ValueError(f"target scene has {len(scene.objects)} objects; n_max is {n}")
    alive = np.zeros(n, bool)
    shape = np.zeros(n, np.int32)
    color = np.zeros(n, np.int32)
    pos = np.zeros((n, 2), np.float32)
    for i, o in enumerate(scene.objects):
        alive[i] = True
        shape[i], color[i] = SHAPES.index(o.shape), COLORS.index(o.color)
        pos[i] = o.x * cfg.units, o.y * cfg.units
    return Target(jnp.asarray(alive), jnp.asarray(shape), jnp.asarray(color), jnp.asarray(pos))


BAND = 0.25  # squared position units around tau where float32 is not trusted: ASK


def verdict(cfg: VCCConfig, c: SceneConst, b: Blackboard, t: Target) -> jax.Array:
    """NO / YES / ASK for one state's blackboard against one target (not failed is checked
    apart; a search passes the blackboard alone, `search.packing.unpack_blackboard`)."""
    d = centres(c, b, cfg).astype(jnp.float32)[:, None, :] - t.pos[None, :, :]
    d2 = jnp.sum(d * d, axis=-1)
    tau2 = (cfg.tau * cfg.units) ** 2
    same = (b.alive[:, None] & t.alive[None, :] & (c.shape[:, None] == t.shape[None, :])
            & (b.color[:, None] == t.color[None, :]))
    ok = same & (d2 <= tau2 - BAND)
    unsure = jnp.any(same & (jnp.abs(d2 - tau2) < BAND))  # on the edge of tau: the host decides
    rows, cols = ok.sum(1), ok.sum(0)
    same_count = b.alive.sum() == t.alive.sum()
    missing = jnp.any(b.alive & (rows == 0)) | jnp.any(t.alive & (cols == 0))
    unique = jnp.all(rows <= 1) & jnp.all(cols <= 1)
    return jnp.where(~same_count, NO, jnp.where(unsure | ~unique, ASK, jnp.where(missing, NO, YES))).astype(jnp.int32)
