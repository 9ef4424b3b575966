"""Property tests: the JAX emulator (jit, vmap) and the reference agree on every case.

Seeded random scenes and random programs (bigram walks over the reference programs
with noise, loops included; half of them steered to run deep): the two machines must
agree on failure, the failing index and the whole final state, which includes the
output scene exactly (positions are integers, so "within tau" holds a fortiori).
"""

from __future__ import annotations

import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from tests.helpers import agree, same_jax

from vccjax.machine import step as emulator
from vccjax.machine.config import DEFAULT_CONFIG as CFG
from vccjax.world.programs import random_deep_program, random_program
from vccjax.world.scenes import random_scene
from vccjax.machine.instructions import N_OPS, NAMES
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import scenes_match
from vccjax.machine.state import init_state, load_scene, output_scene, stack

LENGTH = 32  # programs are padded to this length: one compiled shape for every case
BATCH = 500


def make_cases(seed: int, n: int, cfg=CFG):
    rng = np.random.default_rng(seed)
    cases = []
    for _ in range(n):
        sc = random_scene(rng, (1, 8), pointer=bool(rng.random() < 0.6), cfg=cfg)
        if rng.random() < 0.6:
            prog = random_deep_program(rng, sc, max_len=LENGTH - 4, cfg=cfg)
        else:
            prog = random_program(rng, max_len=LENGTH - 4, noise=0.3)
        cases.append((sc, prog))
    return cases


def check_cases(cases, cfg=CFG, batch=BATCH) -> dict:
    stats = {"failed": 0, "loops": 0, "moved": 0}
    for start in range(0, len(cases), batch):
        chunk = cases[start : start + batch]
        chunk = chunk + [chunk[-1]] * (batch - len(chunk))  # keep one batch shape
        consts = stack([load_scene(sc, cfg) for sc, _ in chunk])
        arrays = [p.arrays(LENGTH) for _, p in chunk]
        ops = jnp.asarray(np.stack([a[0] for a in arrays]))
        args = jnp.asarray(np.stack([a[1] for a in arrays]))
        out = jax.device_get(emulator.run_programs(cfg, consts, ops, args))
        host_consts = jax.device_get(consts)
        for i, (sc, prog) in enumerate(chunk[: min(batch, len(cases) - start)]):
            ref = RefMachine(sc, cfg).run(prog)
            st = jax.tree.map(lambda x: x[i], out)
            c = jax.tree.map(lambda x: x[i], host_consts)
            agree(ref, st, f" on case {start + i}: {prog}\nscene {sc}")
            stats["failed"] += ref.failed
            stats["loops"] += "loop_end" in prog.text()
            if not ref.failed:
                mine = output_scene(c, st, cfg)
                assert scenes_match(mine, ref.output_scene(), cfg.tau)
                mine.validate(cfg)  # objects stay inside the workspace and never overlap
                stats["moved"] += not scenes_match(mine, sc, cfg.tau)
    return stats


def test_both_machines_hold_the_same_memories_under_the_same_names():
    """One vocabulary: the same memories and fields in both machines (JAX's padded arrays
    cut by their length fields), equal before any instruction; a difference is named."""
    from vccjax.machine.memories import MEMORIES, first_difference, memories

    ref, st = RefMachine(random_scene(np.random.default_rng(0), 3)), init_state(CFG)
    assert tuple(memories(st)) == MEMORIES and memories(ref) == memories(st)
    ref.hand.held = 2
    assert first_difference(memories(ref), memories(st)) == "hand.held: 2 != -1"


def test_jax_and_reference_agree_on_2000_random_cases():
    stats = check_cases(make_cases(seed=2026, n=2000))
    # the cases must exercise both outcomes, loops and real changes, or the test proves little
    assert 200 < stats["failed"] < 1800, stats
    assert stats["loops"] >= 100, stats
    assert stats["moved"] >= 300, stats


@pytest.mark.parametrize("raster", [32, 48, 128])
def test_agreement_at_other_raster_sizes(raster):
    """The raster is configurable: one word per row (32), a partial second word (48), four (128)."""
    from vccjax.machine.config import VCCConfig

    cfg = VCCConfig(raster=raster)
    stats = check_cases(make_cases(seed=raster, n=150, cfg=cfg), cfg, batch=150)
    assert stats["moved"] >= 20, stats


@pytest.mark.slow
def test_jax_and_reference_agree_on_20000_random_cases():
    stats = check_cases(make_cases(seed=7, n=20000))
    assert stats["loops"] >= 1000, stats


def test_step_batch_grouped_by_instruction_matches_whole_program_runs():
    """What the search does: step many states, one instruction group at a time."""
    cases = make_cases(seed=11, n=256)
    consts = stack([load_scene(sc) for sc, _ in cases])
    arrays = [p.arrays(LENGTH) for _, p in cases]
    ops = np.stack([a[0] for a in arrays])
    args = jnp.asarray(np.stack([a[1] for a in arrays]))
    states = stack([init_state(CFG)] * len(cases))
    for t in range(LENGTH):
        for op in np.unique(ops[:, t]):
            if op < 0:
                continue
            stepped = emulator.step_batch(CFG, consts, states, int(op), args[:, t])
            pick = jnp.asarray(ops[:, t] == op)
            states = jax.tree.map(
                lambda new, old: jnp.where(pick.reshape((-1,) + (1,) * (new.ndim - 1)), new, old),
                stepped, states,
            )
    whole = emulator.run_programs(CFG, consts, jnp.asarray(ops), args)
    host_s, host_w = jax.device_get((states, whole))
    for i in range(len(cases)):
        pick = lambda t: jax.tree.map(lambda x: x[i], t)  # noqa: E731
        assert same_jax(pick(host_s), pick(host_w)), i


def test_run_batch_shares_one_program_over_scenes():
    rng = np.random.default_rng(5)
    scenes = [random_scene(rng, (2, 6), pointer=True) for _ in range(64)]
    prog = random_deep_program(rng, scenes[0], max_len=20)
    o, a, _ = prog.arrays(LENGTH)
    out = jax.device_get(emulator.run_batch(CFG, stack([load_scene(s) for s in scenes]),
                                            jnp.asarray(o), jnp.asarray(a)))
    for i, sc in enumerate(scenes):
        agree(RefMachine(sc).run(prog), jax.tree.map(lambda x: x[i], out))


def test_no_retracing_across_programs_and_scenes():
    """Different programs and scenes of the same padded shape reuse one trace."""
    traced = jax.jit(chex.assert_max_traces(emulator._run, n=1), static_argnums=0)
    rng = np.random.default_rng(3)
    before = emulator.run_program._cache_size()
    for _ in range(5):
        sc = random_scene(rng, (1, 8), pointer=True)
        o, a, _ = random_deep_program(rng, sc, max_len=20).arrays(LENGTH)
        c = load_scene(sc)
        traced(CFG, c, jnp.asarray(o), jnp.asarray(a)).control.failed.block_until_ready()
        emulator.run_program(CFG, c, jnp.asarray(o), jnp.asarray(a)).control.failed.block_until_ready()
    assert emulator.run_program._cache_size() - before <= 1
    step_traced = jax.jit(chex.assert_max_traces(emulator.step, n=1), static_argnums=0)
    s = init_state(CFG)
    for op in range(N_OPS):  # the op is data: one trace serves every instruction
        s = step_traced(CFG, c, s, jnp.int32(op), jnp.int32(0))


def test_derived_raster_masks_and_grid_match_the_reference_pixels():
    """The full-resolution masks derived from the JAX state are the reference's pixel sets,
    after motion too; the 15x15 grid cell is floor(position * 14)."""
    from vccjax.machine.motion import imagined_runs
    from vccjax.machine.state import grid15, object_masks

    rng = np.random.default_rng(17)
    checked = 0
    for _ in range(40):
        sc = random_scene(rng, (2, 8), pointer=True)
        prog = random_deep_program(rng, sc, max_len=20, p_fail=0.0)
        ref = RefMachine(sc).run(prog)
        if ref.failed:
            continue
        c = load_scene(sc)
        o, a, _ = prog.arrays(LENGTH)
        st = emulator.run_program(CFG, c, jnp.asarray(o), jnp.asarray(a))
        masks = np.asarray(object_masks(c, st, CFG))
        cells = np.asarray(grid15(c, st, CFG))
        for i, alive in enumerate(ref.blackboard.alive):
            want = np.zeros((CFG.raster, CFG.raster), bool)
            if alive:
                rows, cols = zip(*ref.pixels(i))
                want[list(rows), list(cols)] = True
                assert tuple(cells[i]) == tuple(v * 14 // CFG.units for v in ref.centre(i))
            assert (masks[i] == want).all(), (i, prog)
        imag = np.zeros((CFG.raster, CFG.raster), bool)
        for r, col in ref.imagined_set():
            imag[r, col] = True
        b = st.blackboard
        assert np.array_equal(np.asarray(imagined_runs(b.imagined_kind, b.imagined_position, CFG)[0]), _lines(imag))
        checked += 1
    assert checked >= 20


@pytest.mark.parametrize("holding", [False, True])
def test_carry_ops_skip_the_carry_only_when_nothing_is_held(holding):
    """`search.stepping.EMPTY_HANDED`: a search batch with no object held runs a cheaper
    stand-in; it must give what the full op gives (and what the reference gives)."""
    from search.stepping import EMPTY_HANDED, step_examples
    from vccjax.machine.program import parse

    rng = np.random.default_rng(21)
    scenes = [random_scene(rng, (2, 6), pointer=True) for _ in range(16)]
    prefix = "scene_parse; top_down_attend; fixate_attended_object; move_hand_to_attended_object"
    prefix += "; grab_object" if holding else ""
    consts = stack([load_scene(s) for s in scenes])
    states = emulator.run_batch(CFG, consts, *(jnp.asarray(a) for a in parse(prefix).arrays(LENGTH)[:2]))
    assert bool(jnp.any(states.hand.held >= 0)) == holding
    one_example = lambda t: jax.tree.map(lambda x: x[:, None], t)  # noqa: E731  each scene a task of 1 example
    tasks, zeros = jnp.arange(len(scenes)), jnp.zeros(len(scenes), jnp.int32)
    for op in EMPTY_HANDED:
        batched = step_examples(CFG, op, one_example(consts), tasks, one_example(states), zeros)
        batched = jax.tree.map(lambda x: x[:, 0], batched)
        full = jax.vmap(lambda c, s, op=op: emulator.step_op(CFG, c, s, op, jnp.int32(0)))(consts, states)
        host_b, host_f = jax.device_get((batched, full))
        for i, sc in enumerate(scenes):
            pick = lambda t, i=i: jax.tree.map(lambda x: x[i], t)  # noqa: E731
            ref = RefMachine(sc).run(parse(f"{prefix}; {NAMES[op]}"))
            assert same_jax(pick(host_b), pick(host_f))
            agree(ref, pick(host_b))


def _lines(m: np.ndarray) -> np.ndarray:
    """First and last pixel of each line of a mask (1, 0: an empty line)."""
    any_ = m.any(1)
    lo, hi = np.argmax(m, 1), CFG.raster - 1 - np.argmax(m[:, ::-1], 1)
    return np.stack([np.where(any_, lo, 1), np.where(any_, hi, 0)], 1)


def test_imagined_runs_in_closed_form_are_the_footprint_lines():
    """Contact remakes the imagined object's per-line runs from its kind and position in
    closed form; they must be exactly the lines of the footprint (geometry.imagined_pixels),
    at any position (off the workspace too) and for no imagined object."""
    from vccjax.machine.geometry import imagined_pixels
    from vccjax.machine.motion import imagined_runs

    runs = jax.jit(jax.vmap(lambda k, a: imagined_runs(k, a, CFG)))
    u = CFG.units
    rng = np.random.default_rng(3)
    at = np.concatenate([rng.integers(-40, u + 40, (400, 2)), [[0, 0], [u, u], [u // 2, u // 2]]]).astype(np.int32)
    for kind in (-1, 0, 1):
        rows, cols = jax.tree.map(np.asarray, runs(np.full(len(at), kind, np.int32), at))
        painted = 0
        for (x, y), r, c in zip(at, rows, cols):
            m = np.zeros((CFG.raster, CFG.raster), bool)
            if kind >= 0:
                m[imagined_pixels(kind, int(x), int(y), CFG)] = True
            assert np.array_equal(_lines(m), r) and np.array_equal(_lines(m.T), c), (kind, x, y)
            painted += m.any()
        assert (painted > 0) == (kind >= 0)
