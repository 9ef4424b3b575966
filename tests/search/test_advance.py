"""The search's step (`search.stepping.advance_atoms`): with one column, each row stepped
by its own instruction and the loops it closes replayed, all in one call through one
switch, ends exactly where the machine's own step of that instruction ends
(`step_examples` with its loop replay); padding rows are left as they came; and
programs stepped atom by atom through it, or by all their atoms in one call, end where
the machine's run of the whole program ends."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from search.stepping import advance_atoms, step_examples
from vccjax.machine.config import DEFAULT_CONFIG as CFG
from vccjax.machine.instructions import OP
from vccjax.machine.program import parse
from vccjax.machine.state import init_state, load_scene, stack
from vccjax.machine.step import pad_length, run_batch
from vccjax.world.concepts import reference_program
from vccjax.world.scenes import random_scene

# starts: empty-handed, holding an object (the carry ops carry, others fail), inside an
# open loop (the step records), and a loop body complete but for its loop_end
STARTS = {
    "parsed": "scene_parse",
    "holding": "scene_parse; top_down_attend; move_hand_to_attended_object; grab_object",
    "in_loop": "scene_parse; loop_start; top_down_attend",
    "body_done": "scene_parse; loop_start; top_down_attend; move_hand_to_attended_object; grab_object; "
                 "move_hand_left; release_object; next_object",
}
OPS = [("move_hand_left", 0), ("move_hand_to_pointer", 0), ("release_object", 0), ("next_object", 0),
       ("fill_color", 2), ("grab_object", 0), ("move_hand_to_attended_object", 0), ("loop_start", 0),
       ("loop_end", 0), ("set_color_attn", 1)]


def _bank(scenes):
    return jax.tree.map(lambda a: a[None], stack([load_scene(s) for s in scenes]))  # one task, E examples


def _stepped(bank, examples, text):
    one = jnp.zeros(1, jnp.int32)
    s = jax.tree.map(lambda a: a[None], jax.vmap(lambda _: init_state(CFG))(jnp.arange(examples)))
    prefix = parse(text, check_loops=False)  # a search prefix may end inside a loop
    for op, arg in zip(prefix.ops, prefix.args, strict=True):
        s = step_examples(CFG, op, bank, one, s, jnp.asarray([arg], jnp.int32))
    return s


def test_rows_of_different_instructions_step_as_the_machine_steps_each():
    rng = np.random.default_rng(3)
    bank = _bank([random_scene(rng, n, pointer=True) for n in (2, 4, 6)])
    starts = {name: _stepped(bank, 3, text) for name, text in STARTS.items()}
    assert bool((starts["holding"].hand.held >= 0).all()) and not bool(starts["body_done"].control.failed.any())
    rows = [(op, arg, start) for op, arg in OPS for start in STARTS]
    padding = 3  # rows past `real`: left as they came
    batch = jax.tree.map(lambda *a: jnp.concatenate(a), *[starts[s] for *_, s in rows],
                         *[starts["holding"]] * padding)
    ops = jnp.asarray([OP[o] for o, *_ in rows] + [OP["grab_object"]] * padding, jnp.int32)
    args = jnp.asarray([a for _, a, _ in rows] + [0] * padding, jnp.int32)
    tasks = jnp.zeros(len(ops), jnp.int32)
    out = advance_atoms(CFG, bank, tasks, batch, ops[:, None], args[:, None], jnp.int32(len(rows)))
    one = jnp.zeros(1, jnp.int32)
    outcomes = set()
    for k, (name, arg, start) in enumerate(rows):
        alone = step_examples(CFG, OP[name], bank, one, starts[start], jnp.asarray([arg], jnp.int32))  # replays too
        got = jax.tree.map(lambda a, k=k: a[k : k + 1], out)
        failed = bool(jnp.any(alone.control.failed))
        outcomes.add((name == "loop_end", failed))
        assert bool(jnp.any(got.control.failed)) == failed, (name, start)
        if not failed:  # a program failed somewhere is dead: its loop is not replayed further
            for g, w in zip(jax.tree.leaves(got), jax.tree.leaves(alone), strict=True):
                np.testing.assert_array_equal(np.asarray(g), np.asarray(w), err_msg=f"{name} from {start}")
    assert (True, False) in outcomes and (False, True) in outcomes and (False, False) in outcomes
    for k in range(padding):
        tail = jax.tree.map(lambda a, k=k: a[len(rows) + k], out)
        for g, w in zip(jax.tree.leaves(tail), jax.tree.leaves(starts["holding"]), strict=True):
            np.testing.assert_array_equal(np.asarray(g), np.asarray(w)[0])


PROGRAMS = [
    reference_program("move_all_yellow_left").text(),  # carries inside the body
    reference_program("change_red_objs_color").text(),  # a filter, then a loop
    "scene_parse; loop_start; top_down_attend; move_hand_to_attended_object; grab_object; move_hand_to_pointer; "
    "next_object; loop_end",  # fails where a second object is grabbed while holding, or with no pointer
    # imagination in the body (the last two instructions a body may record)
    "scene_parse; fixate(top); loop_start; top_down_attend; imagine_object(hline); reset_imagination; "
    "next_object; loop_end",
]


@pytest.mark.parametrize("text", PROGRAMS)
def test_programs_stepped_atom_by_atom_end_where_the_whole_run_ends(text):
    """Each scene a row of one example, stepped one atom per call as the search does."""
    program = parse(text)
    rng = np.random.default_rng(len(text))
    scenes = [random_scene(rng, n, pointer=bool(n % 2)) for n in (1, 2, 3, 5, 6, 7, 8)]
    consts = stack([load_scene(s) for s in scenes])
    bank = jax.tree.map(lambda a: a[:, None], consts)  # a task per scene
    tasks = jnp.arange(len(scenes), dtype=jnp.int32)
    states = jax.tree.map(lambda a: a[:, None], jax.vmap(lambda _: init_state(CFG))(tasks))
    real = jnp.int32(len(scenes))
    for op, arg in zip(program.ops, program.args, strict=True):
        states = advance_atoms(CFG, bank, tasks, states, jnp.full((len(tasks), 1), op, jnp.int32),
                               jnp.full((len(tasks), 1), arg, jnp.int32), real)
    ops, args, _ = program.arrays(pad_length(len(program.ops)))
    whole = run_batch(CFG, consts, jnp.asarray(ops), jnp.asarray(args))
    ran = ~np.asarray(whole.control.failed)
    assert ran.any() and (ran.all() or "pointer" in text)
    stepped, whole = jax.device_get((jax.tree.map(lambda a: a[:, 0], states), whole))
    np.testing.assert_array_equal(stepped.control.failed, whole.control.failed)
    for got, want in zip(jax.tree.leaves(stepped), jax.tree.leaves(whole), strict=True):
        np.testing.assert_array_equal(got[ran], want[ran])  # a failed row stops where it failed


def test_rows_of_different_programs_stepped_by_all_their_atoms_in_one_call_end_where_each_run_ends():
    """`advance_atoms`: each row its own program (its atoms -1 padded), in one call or cut
    into two calls of columns, ends where the machine's run of that program ends."""
    rng = np.random.default_rng(11)
    programs = [parse(t) for t in PROGRAMS] + [parse("scene_parse; top_down_attend; fill_color(blue)")]
    rows = [(p, random_scene(rng, n, pointer=bool(k % 2))) for p in programs for k, n in enumerate((2, 5, 7))]
    consts = stack([load_scene(s) for _, s in rows])
    bank = jax.tree.map(lambda a: a[:, None], consts)  # a task per row
    tasks = jnp.arange(len(rows), dtype=jnp.int32)
    width = max(len(p.ops) for p in programs)
    ops = np.full((len(rows) + 2, width), -1, np.int32)  # two padding rows past `real`
    args = np.zeros_like(ops)
    for i, (p, _) in enumerate(rows):
        ops[i, : len(p.ops)], args[i, : len(p.args)] = p.ops, p.args
    tasks = jnp.concatenate([tasks, jnp.zeros(2, jnp.int32)])
    start = jax.tree.map(lambda a: a[:, None], jax.vmap(lambda _: init_state(CFG))(tasks))
    real = jnp.int32(len(rows))
    once = advance_atoms(CFG, bank, tasks, start, jnp.asarray(ops), jnp.asarray(args), real)
    cut = 3
    twice = advance_atoms(CFG, bank, tasks, start, jnp.asarray(ops[:, :cut]), jnp.asarray(args[:, :cut]), real)
    twice = advance_atoms(CFG, bank, tasks, twice, jnp.asarray(ops[:, cut:]), jnp.asarray(args[:, cut:]), real)
    once, twice, start = jax.device_get((once, twice, start))
    fails = set()
    for i, (p, _) in enumerate(rows):
        o, a, _ = p.arrays(pad_length(len(p.ops)))
        whole = jax.device_get(run_batch(CFG, jax.tree.map(lambda x, i=i: x[i : i + 1], consts),
                                         jnp.asarray(o), jnp.asarray(a)))
        failed = bool(whole.control.failed[0])
        fails.add(failed)
        for got in (once, twice):
            assert bool(got.control.failed[i, 0]) == failed, p.text()
            if not failed:
                for g, w in zip(jax.tree.leaves(got), jax.tree.leaves(whole), strict=True):
                    np.testing.assert_array_equal(g[i, 0], w[0], err_msg=p.text())
    assert fails == {True, False}
    for g, w in zip(jax.tree.leaves(once), jax.tree.leaves(start), strict=True):
        np.testing.assert_array_equal(g[len(rows):], w[len(rows):])  # padding left as it came
