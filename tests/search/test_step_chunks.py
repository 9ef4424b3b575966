"""The fused step (`search.stepping.step_chunks`): rows in chunks of one instruction each,
all stepped in one call, end exactly where stepping each instruction's rows alone
(`step_examples`) ends; chunks past `n_chunks` are left as they came."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from search.stepping import STEP_CHUNK, step_chunks, step_examples
from vccjax.machine.config import DEFAULT_CONFIG as CFG
from vccjax.machine.instructions import OP
from vccjax.machine.program import parse
from vccjax.machine.state import init_state, load_scene, stack
from vccjax.world.scenes import random_scene

# a prefix that leaves an object held, so the carry ops carry (and others fail)
PREFIX = "scene_parse; top_down_attend; move_hand_to_attended_object; grab_object"
OPS = ["move_hand_left", "move_hand_to_pointer", "release_object", "next_object", "fill_color", "grab_object",
       "move_hand_to_attended_object", "loop_start"]


def test_chunks_of_different_instructions_step_as_each_alone():
    rng = np.random.default_rng(3)
    scenes = [random_scene(rng, n, pointer=True) for n in (2, 4, 6)]
    bank = jax.tree.map(lambda a: a[None], stack([load_scene(s) for s in scenes]))  # one task, E examples
    root = jax.tree.map(lambda a: a[None], jax.vmap(lambda _: init_state(CFG))(jnp.arange(len(scenes))))
    one = jnp.zeros(1, jnp.int32)
    states = [root]
    for op, arg in zip(parse(PREFIX).ops, parse(PREFIX).args, strict=True):
        states.append(step_examples(CFG, op, bank, one, states[-1], jnp.asarray([arg], jnp.int32)))
    parsed, held = states[1], states[-1]
    assert not bool(held.control.failed.any()) and bool((held.hand.held >= 0).all())
    starts = [parsed, held]  # every op from an empty-handed and from a holding state
    rows = [(OPS[k // 2], starts[k % 2]) for k in range(2 * len(OPS))]
    n = len(rows) * STEP_CHUNK + STEP_CHUNK  # one chunk per (op, start), then a chunk of padding
    batch = jax.tree.map(lambda *a: jnp.concatenate([jnp.repeat(x, STEP_CHUNK, axis=0) for x in a] + [a[0]] * STEP_CHUNK),
                          *[s for _, s in rows])
    ops = np.array([OP[o] for o, _ in rows] + [OP["grab_object"]], np.int32)
    args = jnp.full(n, 2, jnp.int32)  # fill_color's colour; the others take none
    tasks = jnp.zeros(n, jnp.int32)
    out = step_chunks(CFG, bank, tasks, batch, jnp.asarray(ops), args, jnp.int32(len(rows)))
    for k, (name, start) in enumerate(rows):
        alone = step_examples(CFG, OP[name], bank, one, start, args[:1])
        got = jax.tree.map(lambda a, k=k: a[k * STEP_CHUNK : (k + 1) * STEP_CHUNK], out)
        for g, w in zip(jax.tree.leaves(got), jax.tree.leaves(alone), strict=True):
            np.testing.assert_array_equal(np.asarray(g), np.broadcast_to(np.asarray(w), g.shape), err_msg=name)
    tail = jax.tree.map(lambda a: a[-STEP_CHUNK:], out)
    for g, w in zip(jax.tree.leaves(tail), jax.tree.leaves(rows[0][1]), strict=True):  # the padding: untouched
        np.testing.assert_array_equal(np.asarray(g), np.broadcast_to(np.asarray(w), g.shape))
    failed = np.asarray(out.control.failed[: len(rows) * STEP_CHUNK : STEP_CHUNK]).any(axis=1)
    assert failed.any() and not failed.all()  # some ops fail from some starts, others run
