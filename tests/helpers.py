"""Helpers the tests share: build scenes tersely, run a program on both machines and
compare their memories field by field."""

from __future__ import annotations


import jax.numpy as jnp

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.memories import first_difference, memories
from vccjax.machine.program import Program, parse
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, SceneObject, scenes_match
from vccjax.machine.state import VCCState, load_scene, output_scene
from vccjax.machine.step import pad_length, run_program


def obj(shape: str, color: str, x: float, y: float, w: float = 0.1) -> SceneObject:
    return SceneObject(shape, color, x, y, w)


def scene(*objects: SceneObject, pointer=None) -> Scene:
    return Scene(tuple(objects), pointer)


def agree(ref: RefMachine, st: VCCState, what: str = "") -> None:
    """Assert the two machines hold the same memories, field by field (of a failed machine,
    whether and where it failed); name the first field where they part."""
    a, b = memories(ref, failed_rule=True), memories(st, failed_rule=True)
    where = first_difference(a, b)
    assert where is None, f"reference and JAX disagree{what} at {where}:\nref {a}\njax {b}"


def same_jax(s: VCCState, t: VCCState) -> bool:
    """Two (unbatched) JAX states agree as `agree` compares them."""
    return memories(s, failed_rule=True) == memories(t, failed_rule=True)


def run_both(program: Program | str, sc: Scene, cfg: VCCConfig = DEFAULT_CONFIG):
    """Run on the reference and on the jitted JAX emulator; assert they agree; return both."""
    if isinstance(program, str):
        program = parse(program, check_loops=False)
    ref = RefMachine(sc, cfg).run(program)
    c = load_scene(sc, cfg)
    ops, args, _ = program.arrays(pad_length(len(program)))
    st = run_program(cfg, c, jnp.asarray(ops), jnp.asarray(args))
    agree(ref, st, f" on {program}")
    if not ref.failed:  # the output scenes too: the objects' shapes (scene constants) included
        assert scenes_match(output_scene(c, st, cfg), ref.output_scene(), 1e-9), program
    return ref, st


def reference_pairs(program: str, scenes: list[Scene]) -> list[tuple[Scene, Scene]]:
    """(input, output) of the reference machine running `program` on each scene; a failing
    run is no example."""
    p, out = parse(program), []
    for s in scenes:
        m = RefMachine(s).run(p)
        if not m.failed:
            out.append((s, m.output_scene()))
    return out
