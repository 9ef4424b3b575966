"""The search's loop replay (`search.stepping.replay_loops`): a program stepped one
instruction at a time as the search steps it (a `loop_end` only closes the loop, then
every further iteration is replayed in one call) ends in exactly the state the
machine's own run of the whole program reaches (`run_batch`, loops in its traced
control flow), on scenes with one object up to many, with a pointer or without."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from search.stepping import replay_loops, step_examples
from vccjax.machine.config import DEFAULT_CONFIG as CFG
from vccjax.machine.instructions import OP
from vccjax.machine.program import parse
from vccjax.machine.state import init_state, load_scene, stack
from vccjax.machine.step import pad_length, run_batch
from vccjax.world.concepts import reference_program
from vccjax.world.scenes import random_scene

PROGRAMS = [
    reference_program("change_all_objs_color").text(),  # the loop runs once per object
    reference_program("move_all_yellow_left").text(),  # carries inside the body
    # fails in a replayed iteration where a second object exists (the hand still holds the
    # first when it grabs again), runs through on one object, fails early without a pointer
    "scene_parse; loop_start; top_down_attend; move_hand_to_attended_object; grab_object; move_hand_to_pointer; "
    "next_object; loop_end",
    # a body that differs in length from the others, ending in a fixation
    "scene_parse; set_color_attn(red); loop_start; top_down_attend; fixate_attended_object; next_object; loop_end",
    # imagination in the body (the last two instructions a body may record)
    "scene_parse; fixate(top); loop_start; top_down_attend; imagine_object(hline); reset_imagination; "
    "next_object; loop_end",
]


def _scenes(seed: int) -> list:
    rng = np.random.default_rng(seed)
    return [random_scene(rng, n, pointer=bool(n % 2)) for n in (1, 2, 3, 5, 6, 6, 7, 8)]


def _closed_and_replayed(program, bank, task, states):
    """Step `program` as the search does; return the states after the last replay and
    whether some replay changed anything."""
    replayed = False
    for op, arg in zip(program.ops, program.args, strict=True):
        closing = op == OP["loop_end"]
        states = step_examples(CFG, op, bank, task, states, jnp.full(task.shape, arg, jnp.int32), not closing)
        if closing:
            closed = states
            states = replay_loops(CFG, bank, task, states)
            replayed |= any(bool(jnp.any(a != b)) for a, b in zip(jax.tree.leaves(closed), jax.tree.leaves(states)))
    return states, replayed


@pytest.mark.parametrize("text", PROGRAMS)
def test_replayed_loops_end_where_the_whole_program_run_ends(text):
    """Each scene a row of one example (a row that fails on its example is dead, so
    scenes that fail must not share a row with scenes that run on)."""
    program = parse(text)
    assert "loop_start" in text
    scenes = _scenes(len(text))
    consts = stack([load_scene(s) for s in scenes])  # (E, ...)
    bank = jax.tree.map(lambda a: a[:, None], consts)  # E tasks of one example each
    task = jnp.arange(len(scenes), dtype=jnp.int32)
    root = jax.tree.map(lambda a: a[:, None], jax.vmap(lambda _: init_state(CFG))(task))
    states, replayed = _closed_and_replayed(program, bank, task, root)
    assert replayed  # some scene runs a second iteration: the replay is exercised
    ops, args, _ = program.arrays(pad_length(len(program.ops)))
    whole = run_batch(CFG, consts, jnp.asarray(ops), jnp.asarray(args))
    stepped, whole = jax.device_get((jax.tree.map(lambda a: a[:, 0], states), whole))
    for got, want in zip(jax.tree.leaves(stepped), jax.tree.leaves(whole), strict=True):
        np.testing.assert_array_equal(got, want)
    failed = np.asarray(whole.control.failed)
    if "move_hand_to_pointer" in text:  # the case meant to fail on some scenes, and run on others
        assert failed.any() and not failed.all()


def test_a_program_that_failed_on_one_example_replays_no_further():
    """A row's program failed on one example (no pointer there): the search drops it, so
    the replay runs none of its examples further, and it stays failed."""
    program = parse(PROGRAMS[2])  # fails at once on a scene without a pointer
    scenes = [s for s in _scenes(3) if len(s.objects) > 2]
    assert any(s.pointer is None for s in scenes) and any(s.pointer is not None for s in scenes)
    consts = stack([load_scene(s) for s in scenes])
    bank = jax.tree.map(lambda a: a[None], consts)  # one task of E examples
    task = jnp.zeros(1, jnp.int32)
    root = jax.tree.map(lambda a: a[None], jax.vmap(lambda _: init_state(CFG))(jnp.arange(len(scenes))))
    states, replayed = _closed_and_replayed(program, bank, task, root)
    assert not replayed and bool(jnp.any(states.control.failed))
    alone = jnp.asarray([s.pointer is not None for s in scenes])  # the same scenes, each a row of its own
    task_ids = jnp.arange(len(scenes), dtype=jnp.int32)
    rows, _ = _closed_and_replayed(program, jax.tree.map(lambda a: a[:, None], consts), task_ids,
                                   jax.tree.map(lambda a: a[:, None], jax.vmap(lambda _: init_state(CFG))(task_ids)))
    assert bool(jnp.any(rows.hand.position[alone, 0] != states.hand.position[0, alone]))  # alone, they ran on


def test_one_replay_call_serves_rows_with_different_bodies():
    """Programs whose loops have different bodies, closed separately and replayed together
    in one call (as a search round does), each end as its whole run ends (each scene a
    row of one example, as above)."""
    programs = [parse(t) for t in PROGRAMS]
    scenes = _scenes(7)
    consts = stack([load_scene(s) for s in scenes])
    bank = jax.tree.map(lambda a: a[:, None], consts)  # a task per scene
    per_scene = jnp.arange(len(scenes), dtype=jnp.int32)

    def run(states, tasks, ops, args, replay_at_end):
        for k, (op, arg) in enumerate(zip(ops, args, strict=True)):
            last = replay_at_end and k == len(ops) - 1
            states = step_examples(CFG, op, bank, tasks, states, jnp.full(tasks.shape, arg, jnp.int32), not last)
        return states

    root = jax.tree.map(lambda a: a[:, None], jax.vmap(lambda _: init_state(CFG))(per_scene))
    ends = [p.ops.index(OP["loop_end"]) + 1 for p in programs]  # each program holds one loop
    closed = [run(root, per_scene, p.ops[:e], p.args[:e], True) for p, e in zip(programs, ends, strict=True)]
    batch = jax.tree.map(lambda *a: jnp.concatenate(a), *closed)  # rows: programs x scenes
    replayed = replay_loops(CFG, bank, jnp.tile(per_scene, len(programs)), batch)
    n = len(scenes)
    for i, (p, e) in enumerate(zip(programs, ends, strict=True)):
        rows = jax.tree.map(lambda a, i=i: a[i * n : (i + 1) * n], replayed)
        final = run(rows, per_scene, p.ops[e:], p.args[e:], False)
        ops, args, _ = p.arrays(pad_length(len(p.ops)))
        whole = run_batch(CFG, consts, jnp.asarray(ops), jnp.asarray(args))
        for got, want in zip(jax.tree.leaves(jax.device_get(final)), jax.tree.leaves(jax.device_get(whole)), strict=True):
            np.testing.assert_array_equal(got[:, 0], want)
