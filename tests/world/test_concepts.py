"""The 546 reference programs: each runs and changes a seeded random scene, on both machines;
two of them traced step by step do what their names say."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from tests.helpers import agree, obj, run_both, scene

from vccjax.machine import step as emulator
from vccjax.world.concepts import LICENSE, all_concepts, concept_names, reference_program
from vccjax.machine.config import DEFAULT_CONFIG as CFG
from vccjax.world.scenes import random_scene
from vccjax.machine.program import check_loop_syntax
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import scenes_match
from vccjax.machine.state import load_scene, stack

TAU = CFG.tau


def test_concept_file_is_complete_and_licensed():
    names = concept_names()
    assert len(names) == 546 and len(set(names)) == 546
    import json
    from importlib import resources

    d = json.loads(resources.files("vccjax.world").joinpath("data/concepts.json").read_text())
    assert d["license"] == LICENSE
    lengths = [len(p) for p in all_concepts().values()]
    assert min(lengths) == 4 and max(lengths) == 23  # the paper's figures
    for p in all_concepts().values():
        check_loop_syntax(p)


def test_every_reference_program_runs_and_changes_a_random_scene():
    """Sweep all 546: find a seeded scene where the program succeeds and changes the scene
    (reference), then run all 546 at once on the JAX emulator and compare."""
    rng = np.random.default_rng(546)
    chosen = {}
    for name, prog in all_concepts().items():
        for _ in range(300):
            sc = random_scene(rng, (2, 6), pointer=True)
            m = RefMachine(sc).run(prog)
            if not m.failed and not scenes_match(m.output_scene(), sc, TAU):
                chosen[name] = (sc, prog, m)
                break
    missing = sorted(set(concept_names()) - set(chosen))
    assert not missing, f"no changing scene found for {missing}"
    items = list(chosen.values())
    consts = stack([load_scene(sc) for sc, _, _ in items])
    arrays = [p.arrays(32) for _, p, _ in items]
    out = jax.device_get(emulator.run_programs(
        CFG, consts, jnp.asarray(np.stack([a[0] for a in arrays])),
        jnp.asarray(np.stack([a[1] for a in arrays]))))
    for i, (name, (_, _, m)) in enumerate(chosen.items()):
        pick = lambda t: jax.tree.map(lambda x: x[i], t)  # noqa: E731
        agree(m, pick(out), f" on {name}")


def _centre(m, i):
    u = CFG.units
    x, y = m.centre(i)
    return x / u, y / u


def test_trace_chained_movement_left_most_object():
    """Leftmost object to the left edge; each next object (by distance from the left
    fixation point) slides into the place the previous one left."""
    sc = scene(obj("square", "red", 0.25, 0.5), obj("circle", "green", 0.45, 0.52),
               obj("triangle", "blue", 0.65, 0.48), obj("star", "yellow", 0.85, 0.5))
    prog = reference_program("chained_movement_left_most_object")
    m = RefMachine(sc)
    seen = []
    for i, (op, arg) in enumerate(zip(prog.ops, prog.args)):
        m.step(op, arg)
        assert not m.failed, (i, m.fail_reason)
        run_both(type(prog)(prog.ops[: i + 1], prog.args[: i + 1]), sc)  # every prefix agrees
        seen.append((prog.steps()[i][0], [_centre(m, j) for j in range(4)], m.fovea.position))
    # after fixate(left) + top_down_attend the leftmost object is attended
    assert seen[2][0] == "top_down_attend" and m.blackboard.alive[0]
    out = m.output_scene().objects
    assert out[0].x - out[0].width / 2 == pytest.approx(0.0, abs=1 / 64)  # at the left edge
    for j in (1, 2, 3):  # each object took its predecessor's place
        assert abs(out[j].x - sc.objects[j - 1].x) <= TAU and abs(out[j].y - sc.objects[j - 1].y) <= TAU
    # the loop ran for the three remaining objects: history = centre, left, then 4 objects
    assert len(m.fovea.history) == 6


def test_trace_swap_locations():
    sc = scene(obj("square", "red", 0.45, 0.5), obj("circle", "blue", 0.8, 0.3, 0.08))
    prog = reference_program("swap_locations")
    m = RefMachine(sc)
    for i, (op, arg) in enumerate(zip(prog.ops, prog.args)):
        m.step(op, arg)
        assert not m.failed, (i, prog.steps()[i], m.fail_reason)
        if prog.steps()[i][0] == "move_hand_down":  # the first object was parked at the bottom
            assert _centre(m, 0)[1] + 0.05 == pytest.approx(1.0, abs=1 / 64)
    run_both(prog, sc)
    a, b = m.output_scene().objects
    assert abs(a.x - 0.8) <= TAU and abs(a.y - 0.3) <= TAU  # red square where the circle was
    assert abs(b.x - 0.45) <= TAU and abs(b.y - 0.5) <= TAU  # blue circle where the square was
