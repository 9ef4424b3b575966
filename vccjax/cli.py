"""The `vcc` command line. User mistakes end in a one-line error and exit code 2."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from vccjax import files, runtime
from vccjax.errors import VCCError
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.views.text import ascii_scene, legend


def program_and_scene(a: argparse.Namespace):
    """(program, scene, note, expected output or None) from the shared flags of `vcc run`
    and `vcc trace`: PROGRAM or --concept; --scene, --image, --example K of the concept,
    or a seeded random scene."""
    from vccjax.world.scenes import random_scene
    from vccjax.world.user_concepts import concept_program
    from vccjax.machine.reference import run_reference
    from vccjax.machine.scene import Scene, scenes_match

    cfg = DEFAULT_CONFIG
    program = None if a.program is None else runtime.program_from_arg(a.program)
    if program is None:
        if not a.concept:
            raise VCCError("give a PROGRAM, or --concept NAME to run its program (shipped or saved by vcc learn)")
        program = concept_program(a.concept)
    given = [f for f, v in (("--scene", a.scene), ("--image", a.image), ("--example", a.example)) if v is not None]
    if len(given) > 1:
        raise VCCError(f"give one of {', '.join(given)}, not several")
    if a.example is not None and not a.concept:
        raise VCCError("--example K takes the K-th example pair of --concept NAME")
    from vccjax.vision.examples_folder import read_scene  # errors name the file

    if a.scene:
        return program, read_scene(a.scene, cfg, image=False), f"scene {a.scene}", None
    if a.image:

        scene = read_scene(a.image, cfg, image=True)
        return program, scene, f"image {a.image} ({len(scene.objects)} objects parsed)", None
    if a.example is not None:
        from vccjax.world.dataset import dataset_for

        pairs = dataset_for([a.concept], 0, a.dataset, progress=False).pairs(a.concept, a.split)
        if not 0 <= a.example < len(pairs):
            raise VCCError(f"--example {a.example}: {a.concept} has {len(pairs)} {a.split} pairs "
                           f"(0 to {len(pairs) - 1})")
        scene, expected = pairs[a.example]
        return program, scene, f"{a.split} example {a.example} of {a.concept}", expected
    # a seeded random scene; with --concept, the first seed on which the concept does
    # something, else the first on which it runs (a concept may change nothing)
    runs = None
    for seed in range(a.seed, a.seed + (500 if a.concept else 1)):
        scene = random_scene(np.random.default_rng(seed), a.objects, pointer=True)
        m = run_reference(program, scene, cfg)
        if not a.concept or (not m.failed and not scenes_match(m.output_scene(), scene, cfg.tau)):
            return program, scene, f"random scene, seed {seed}", None
        if runs is None and not m.failed:
            runs = seed
    seed = a.seed if runs is None else runs
    scene = random_scene(np.random.default_rng(seed), a.objects, pointer=True)
    how = "it fails on every one" if runs is None else "the first it runs on"
    return program, scene, f"random scene, seed {seed} ({a.concept} changes no scene of seeds {a.seed} to " \
                           f"{a.seed + 499}; {how})", None


def cmd_run(a: argparse.Namespace) -> int:
    from vccjax.machine.step import run
    from vccjax.machine.reference import run_reference
    from vccjax.machine.scene import scenes_match
    from vccjax.machine.state import load_scene, output_scene

    cfg = DEFAULT_CONFIG
    program, scene, note, expected = program_and_scene(a)
    if a.engine == "reference":
        m = run_reference(program, scene, cfg)
        failed, index, reason, out = m.failed, m.control.fail_index, m.fail_reason, m.output_scene()
    else:
        c = load_scene(scene, cfg)
        st = run(program, c, cfg)
        failed, index, reason = bool(st.control.failed), int(st.control.fail_index), None
        out = output_scene(c, st, cfg, scene.pointer)
    print(f"program ({len(program)} instructions): {program}")
    print(f"{note}; engine: {a.engine}")
    if failed:
        step = program.steps()[index]
        why = f": {reason}" if reason else ""
        print(f"FAILED at instruction {index} ({step[0]}{'(' + step[1] + ')' if step[1] else ''}){why}")
        return 1
    before, after = ascii_scene(scene, cfg), ascii_scene(out, cfg)
    print(f"{'before':<34}after")
    for left, right in zip(before, after):
        print(f"{left}  {right}")
    print("before:", *legend(scene), sep="\n  ")
    print("after:", *legend(out), sep="\n  ")
    print("changed" if not scenes_match(out, scene, cfg.tau) else "unchanged")
    if expected is not None:
        same = scenes_match(out, expected, cfg.tau)
        print("the example's output: " + ("matched" if same else "NOT matched"))
        return 0 if same else 1
    return 0


def cmd_trace(a: argparse.Namespace) -> int:
    from vccjax.views.trace import trace
    from vccjax.views.viewer import write_trace

    program, scene, note, _ = program_and_scene(a)
    outs = [o for o in a.out.split(",") if o]
    bad = [o for o in outs if Path(o).suffix.lower() not in (".png", ".gif")]
    if bad or not outs:
        raise VCCError(f"--out {a.out}: write a .png sheet or a .gif animation (or both, comma-separated)")
    frames = trace(program, scene)
    for out in outs:
        write_trace(frames, out, size=a.size, columns=a.columns, seconds_per_step=a.seconds)
    last = frames[-1]
    status = (f"FAILED at instruction {last.pc} ({last.instruction}): {last.machine.fail_reason}"
              if last.failed else "ran to the end")
    print(f"{note}: {len(frames) - 1} instructions executed, {status}")
    print("wrote " + ", ".join(outs))
    return 1 if last.failed else 0


def cmd_concepts(a: argparse.Namespace) -> int:
    from vccjax.world.concepts import all_concepts

    shown = 0
    for name, p in all_concepts().items():
        if a.pattern is None or a.pattern.lower() in name.lower():
            print(f"{len(p):3d}  {name}")
            shown += 1
    if not shown:
        print(f"no concept name contains {a.pattern!r} (vcc concepts alone lists all 546)")
    return 0


def cmd_dataset_build(a: argparse.Namespace) -> int:
    import os
    import time

    from vccjax.world.concepts import read_programs
    from vccjax.world.dataset import build_dataset, rival_warnings

    concepts = None if a.concepts in (None, "all") else [c.strip() for c in a.concepts.split(",") if c.strip()]
    programs = read_programs(a.programs) if a.programs else None
    start = time.time()
    m = build_dataset(a.out, concepts, seed=a.seed, workers=a.workers or os.cpu_count() or 1, programs=programs)
    asked = len(concepts) if concepts is not None else len(programs) if programs is not None else len(m["concepts"])
    print(f"{asked} concept(s) built or found intact in {a.out} (seed {a.seed}) in {time.time() - start:.0f}s; "
          f"the dataset holds {len(m['concepts'])}")
    left = m["rivals_left"]
    print(f"training pairs tell every rival of the reference apart in {len(m['concepts']) - len(left)} concepts;"
          f" {len(left)} leave some untold (manifest.json: rivals_left)")
    if programs is not None:
        print("\n".join(rival_warnings(m)))
    for name, why in m["failed"].items():
        print(f"not built: {name}: {why}")
    return 1 if m["failed"] else 0


def cmd_dataset_info(a: argparse.Namespace) -> int:
    from vccjax.world.dataset import Dataset

    ds = Dataset(a.folder)
    for name in ds.concepts:  # verifies every file's hashes
        ds.arrays(name)
    m = ds.manifest
    print(f"{a.folder}: {m['format']} v{m['version']}, seed {m['seed']}, {len(ds.concepts)} concepts verified, "
          f"{len(m['failed'])} not built")
    return 0


def cmd_perception_evaluate(a: argparse.Namespace) -> int:
    import json

    from vccjax.vision.drawings import STYLES as DRAWN
    from vccjax.vision.measure import end_to_end, evaluate, exact_scenes
    from vccjax.vision.render import STYLES as RENDERED

    styles = [s.strip() for s in a.styles.split(",") if s.strip()]
    unknown = [s for s in styles if s not in RENDERED + DRAWN]
    if unknown or not styles:
        raise VCCError(f"--styles {a.styles}: each must be one of {', '.join(RENDERED + DRAWN)}")
    sizes = [int(s) for s in str(a.size).split(",")]
    if a.dataset:  # every file checked before the first progress bar
        from vccjax.world.dataset import Dataset

        ds = Dataset(a.dataset)
        for name in ds.concepts:
            ds.arrays(name)
    results = []
    for style in styles:
        for size in sizes:
            if a.dataset:
                r = end_to_end(a.dataset, style, pairs=a.pairs, size=size, workers=a.workers)
            elif a.touching:
                r = exact_scenes(a.images, style, size, seed=a.seed, touching=True)
            elif a.pointer_on_object:
                r = exact_scenes(a.images, style, size, seed=a.seed, on_object_share=1.0)
            elif style in DRAWN:  # drawn apart from our renderer: the share of scenes parsed exactly
                r = exact_scenes(a.images, style, size, seed=a.seed)
            else:
                r = evaluate(a.images, style, seed=a.seed, size=size)
            results.append(r)
            print(json.dumps(r))
    if a.out:
        Path(a.out).parent.mkdir(parents=True, exist_ok=True)
        command = (f"vcc perception eval --styles {a.styles} --size {a.size} --images {a.images} --seed {a.seed}"
                   + " --touching" * a.touching + " --pointer-on-object" * a.pointer_on_object)
        files.write_json(a.out, {"command": command, "results": results})
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The emulator's commands alone (the full `vcc` adds the other packages': vcc.cli)."""
    p = runtime.Parser(
        prog="vcc",
        description="Visual Cognitive Computer toolkit: run cognitive programs on tabletop scenes.",
    )
    add_commands(p.add_subparsers(dest="command", required=True, metavar="COMMAND"))
    return p


def _scene_flags(p: argparse.ArgumentParser) -> None:
    p.add_argument("program", nargs="?", help="program text or file (default: the concept's reference program)")
    p.add_argument("--concept", metavar="NAME", help="one of the 546 concepts (see `vcc concepts`)")
    p.add_argument("--scene", metavar="FILE", help="scene JSON file")
    p.add_argument("--image", metavar="FILE", help="image file of a scene, parsed by the OpenCV perception")
    p.add_argument("--example", type=runtime.count(0), metavar="K",
                   help="the concept's K-th example pair: its input, checked against its output")
    p.add_argument("--split", choices=["train", "test"], default="train", help="pairs of --example (default train)")
    p.add_argument("--dataset", metavar="DIR", help="built dataset folder for --example (default: the shipped one)")
    p.add_argument("--seed", type=runtime.count(0), default=0,
                   help="seed of the random scene when none is given (default 0)")
    p.add_argument("--objects", type=runtime.count(1, DEFAULT_CONFIG.n_max), default=4,
                   help="objects in the random scene (default 4)")


def add_commands(sub) -> None:
    """run, trace, dataset, perception, concepts."""
    r = sub.add_parser("run", help="run a program on a scene and print it before and after",
                       description="Run a VCC program (text like 'scene_parse; fixate(left); ...' "
                                   "or a .vcc file) on a scene and print it before and after.")
    _scene_flags(r)
    r.add_argument("--engine", choices=["jax", "reference"], default="jax",
                   help="the JAX emulator (default) or the scalar reference interpreter")
    r.set_defaults(fn=cmd_run)
    t = sub.add_parser("trace", help="draw a program's run, one panel per executed instruction (PNG or GIF)",
                       description="Run a program on the reference interpreter and draw every executed "
                                   "instruction (loop iterations included): the blackboard and imagined "
                                   "object, the fovea and its history, the hand and the held object, "
                                   "attention (filters, attended list, the attended object boxed), and "
                                   "the instruction with its argument; a failure is marked in red.")
    _scene_flags(t)
    t.add_argument("--out", required=True, type=runtime.out_file(".png", ".gif", several=True),
                   help="trace.png (a sheet of panels) or trace.gif (animated); "
                                                "both, comma-separated")
    t.add_argument("--size", type=runtime.count(32, 2048), default=256, help="panel width in pixels (default 256)")
    t.add_argument("--columns", type=runtime.count(1, 64), default=6,
                   help="panels per row of the PNG sheet (default 6)")
    t.add_argument("--seconds", type=runtime.number(0, 60, above=True), default=0.8,
                   help="seconds per GIF frame (default 0.8)")
    t.set_defaults(fn=cmd_trace)
    d = sub.add_parser("dataset", help="build or check the concepts' example pairs")
    dsub = d.add_subparsers(dest="action", required=True, metavar="ACTION")
    b = dsub.add_parser("build", help="generate 10 training and 50 test pairs per concept (resumable)")
    b.add_argument("--concepts", type=runtime.name_list, default="all",
                   help="'all' (default) or a comma-separated list")
    b.add_argument("--programs", help="build your own concepts instead: a file of `name: program` lines")
    b.add_argument("--seed", type=runtime.count(0), default=0, help="seed (default 0); same seed, same bytes")
    b.add_argument("--out", default="data/examples", type=runtime.out_folder,
                   help="output folder (default data/examples)")
    b.add_argument("--workers", type=runtime.count(0, 256), default=0, help="processes (default: one per core)")
    b.set_defaults(fn=cmd_dataset_build)
    i = dsub.add_parser("info", help="verify a built dataset and summarise it")
    i.add_argument("folder")
    i.set_defaults(fn=cmd_dataset_info)
    pe = sub.add_parser("perception", help="measure the image parser")
    psub = pe.add_subparsers(dest="action", required=True, metavar="ACTION")
    ev = psub.add_parser("eval", help="accuracy on rendered random scenes, or end to end on a dataset",
                         description="Without --dataset: render N seeded random scenes per style, parse "
                                     "them, report objects recovered (shape, color, centre within tau), "
                                     "images without phantoms, pointers found. With --dataset: run each "
                                     "concept's program on parsed test inputs and compare outputs.")
    ev.add_argument("--styles", default="schematic,varied",
                    help="comma-separated: schematic, varied (our renderer); outline, jitter, photo, shades "
                         "(drawn apart from it, scored as scenes parsed exactly)")
    ev.add_argument("--images", type=runtime.count(1, 10**6), default=5000, help="scenes per style (default 5000)")
    ev.add_argument("--seed", type=runtime.count(0), default=0)
    ev.add_argument("--size", default="384", type=runtime.counts(64, 4096), help="image size in pixels, or several comma-separated (default 384)")
    ev.add_argument("--out", type=runtime.out_file(".json"), help="also write the results to this JSON file")
    ev.add_argument("--dataset", help="a built dataset folder: run the end-to-end check instead")
    ev.add_argument("--touching", action="store_true",
                    help="scenes holding two touching objects of one colour, scored as scenes parsed exactly")
    ev.add_argument("--pointer-on-object", action="store_true",
                    help="every pointer on an object (as attend_pointer examples draw it), scored as scenes "
                         "parsed exactly")
    ev.add_argument("--pairs", type=runtime.count(1, 50), default=50, help="test pairs per concept (end to end)")
    ev.add_argument("--workers", type=runtime.count(1, 256), default=1, help="processes for the end-to-end check")
    ev.set_defaults(fn=cmd_perception_evaluate)
    c = sub.add_parser("concepts", help="list the 546 concepts with their program lengths")
    c.add_argument("pattern", nargs="?", help="only names containing this")
    c.set_defaults(fn=cmd_concepts)


def main(argv: list[str] | None = None, parser: argparse.ArgumentParser | None = None) -> int:
    return runtime.run_command(parser or build_parser(), argv)

if __name__ == "__main__":
    sys.exit(main())
