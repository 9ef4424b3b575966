"""The `vcc` command line. User mistakes end in a one-line error and exit code 2."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from vccjax.config import DEFAULT_CONFIG
from vccjax.errors import VCCError

_SHAPE_CHAR = {"square": "#", "circle": "o", "diamond": "<>", "triangle": "^", "star": "*"}


def ascii_scene(scene, cfg=DEFAULT_CONFIG, size: int = 32) -> list[str]:
    """A scene drawn in characters: each object by its index, the pointer as '+'."""
    from vccjax.geometry import object_pixels
    from vccjax.scene import to_units

    grid = np.full((size, size), ".", dtype="<U1")
    f = cfg.raster // size
    for i, o in enumerate(scene.objects):
        rows, cols = object_pixels(o.shape, o.width, to_units(o.x, cfg), to_units(o.y, cfg), cfg)
        ok = (rows >= 0) & (rows < cfg.raster) & (cols >= 0) & (cols < cfg.raster)
        grid[rows[ok] // f, cols[ok] // f] = str(i % 10)
    if scene.pointer is not None:
        px, py = (min(int(v * size), size - 1) for v in scene.pointer)
        grid[py, px] = "+"
    return ["".join(r) for r in grid]


def _legend(scene) -> list[str]:
    return [f"{i}: {o.color:6s} {o.shape:8s} ({o.x:.3f}, {o.y:.3f}) w {o.width:.3f}"
            for i, o in enumerate(scene.objects)]


def _read_program(text: str | None):
    from vccjax.program import parse

    if text is None:
        return None
    path = Path(text)
    if text.endswith((".vcc", ".txt")) or (path.suffix and path.exists()):
        if not path.exists():
            raise VCCError(f"{path}: no such program file")
        text = path.read_text()
    return parse(text, body_max=DEFAULT_CONFIG.body_max)


def cmd_run(a: argparse.Namespace) -> int:
    from vccjax.concepts import reference_program
    from vccjax.emulator import run
    from vccjax.generate import random_scene
    from vccjax.reference import run_reference
    from vccjax.scene import Scene, scenes_match
    from vccjax.state import load_scene, output_scene

    cfg = DEFAULT_CONFIG
    program = _read_program(a.program)
    if program is None:
        if not a.concept:
            raise VCCError("give a PROGRAM, or --concept NAME to run its reference program")
        program = reference_program(a.concept)
    if a.scene:
        scene, note = Scene.load(a.scene).validate(cfg), f"scene {a.scene}"
    else:
        # a seeded random scene; with --concept, the first seed on which the concept does something
        for seed in range(a.seed, a.seed + 500):
            scene = random_scene(np.random.default_rng(seed), a.objects, pointer=True)
            m = run_reference(program, scene, cfg)
            if not a.concept or (not m.failed and not scenes_match(m.output_scene(), scene, cfg.tau)):
                break
        note = f"random scene, seed {seed}"
    if a.engine == "reference":
        m = run_reference(program, scene, cfg)
        failed, index, reason, out = m.failed, m.fail_index, m.fail_reason, m.output_scene()
    else:
        c = load_scene(scene, cfg)
        st = run(program, c, cfg)
        failed, index, reason = bool(st.failed), int(st.fail_index), None
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
    print("before:", *_legend(scene), sep="\n  ")
    print("after:", *_legend(out), sep="\n  ")
    print("changed" if not scenes_match(out, scene, cfg.tau) else "unchanged")
    return 0


def cmd_concepts(a: argparse.Namespace) -> int:
    from vccjax.concepts import all_concepts

    for name, p in all_concepts().items():
        if a.pattern is None or a.pattern.lower() in name.lower():
            print(f"{len(p):3d}  {name}")
    return 0


def cmd_dataset_build(a: argparse.Namespace) -> int:
    import os
    import time

    from vccjax.dataset import build_dataset

    concepts = None if a.concepts in (None, "all") else [c.strip() for c in a.concepts.split(",") if c.strip()]
    start = time.time()
    m = build_dataset(a.out, concepts, seed=a.seed, workers=a.workers or os.cpu_count() or 1)
    print(f"{len(m['concepts'])} concepts written to {a.out} (seed {a.seed}) in {time.time() - start:.0f}s")
    left = m["rivals_left"]
    print(f"training pairs tell every rival of the reference apart in {len(m['concepts']) - len(left)} concepts;"
          f" {len(left)} leave some untold (manifest.json: rivals_left)")
    for name, why in m["failed"].items():
        print(f"not built: {name}: {why}")
    return 1 if m["failed"] else 0


def cmd_dataset_info(a: argparse.Namespace) -> int:
    from vccjax.dataset import Dataset

    ds = Dataset(a.folder)
    for name in ds.concepts:  # verifies every file's hashes
        ds.arrays(name)
    m = ds.manifest
    print(f"{a.folder}: {m['format']} v{m['version']}, seed {m['seed']}, {len(ds.concepts)} concepts verified, "
          f"{len(m['failed'])} not built")
    return 0


def cmd_perception_evaluate(a: argparse.Namespace) -> int:
    import json

    from vccjax.perception_eval import end_to_end, evaluate

    for style in a.styles.split(","):
        if a.dataset:
            r = end_to_end(a.dataset, style, pairs=a.pairs, size=a.size, workers=a.workers)
        else:
            r = evaluate(a.images, style, seed=a.seed, size=a.size)
        print(json.dumps(r))
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The emulator's commands alone (the full `vcc` adds the other packages': vcc.cli)."""
    p = argparse.ArgumentParser(
        prog="vcc",
        description="Visual Cognitive Computer toolkit: run cognitive programs on tabletop scenes.",
    )
    add_commands(p.add_subparsers(dest="command", required=True, metavar="COMMAND"))
    return p


def add_commands(sub) -> None:
    """run, dataset, perception, concepts."""
    r = sub.add_parser("run", help="run a program on a scene and print it before and after",
                       description="Run a VCC program (text like 'scene_parse; fixate(left); ...' "
                                   "or a .vcc file) on a scene and print it before and after.")
    r.add_argument("program", nargs="?", help="program text or file (default: the concept's reference program)")
    r.add_argument("--concept", help="one of the 546 concepts (see `vcc concepts`)")
    r.add_argument("--scene", help="scene JSON file (default: a seeded random scene)")
    r.add_argument("--seed", type=int, default=0, help="seed of the random scene (default 0)")
    r.add_argument("--objects", type=int, default=4, help="objects in the random scene (default 4)")
    r.add_argument("--engine", choices=["jax", "reference"], default="jax",
                   help="the JAX emulator (default) or the scalar reference interpreter")
    r.set_defaults(fn=cmd_run)
    d = sub.add_parser("dataset", help="build or check the concepts' example pairs")
    dsub = d.add_subparsers(dest="action", required=True, metavar="ACTION")
    b = dsub.add_parser("build", help="generate 10 training and 50 test pairs per concept (resumable)")
    b.add_argument("--concepts", default="all", help="'all' (default) or a comma-separated list")
    b.add_argument("--seed", type=int, default=0, help="seed (default 0); same seed, same bytes")
    b.add_argument("--out", default="data/examples", help="output folder (default data/examples)")
    b.add_argument("--workers", type=int, default=0, help="processes (default: one per core)")
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
    ev.add_argument("--styles", default="schematic,varied", help="comma-separated styles")
    ev.add_argument("--images", type=int, default=5000, help="scenes per style (default 5000)")
    ev.add_argument("--seed", type=int, default=0)
    ev.add_argument("--size", type=int, default=384, help="image size in pixels (default 384)")
    ev.add_argument("--dataset", help="a built dataset folder: run the end-to-end check instead")
    ev.add_argument("--pairs", type=int, default=50, help="test pairs per concept (end to end)")
    ev.add_argument("--workers", type=int, default=1, help="processes for the end-to-end check")
    ev.set_defaults(fn=cmd_perception_evaluate)
    c = sub.add_parser("concepts", help="list the 546 concepts with their program lengths")
    c.add_argument("pattern", nargs="?", help="only names containing this")
    c.set_defaults(fn=cmd_concepts)


def main(argv: list[str] | None = None, parser: argparse.ArgumentParser | None = None) -> int:
    args = (parser or build_parser()).parse_args(argv)
    try:
        return args.fn(args)
    except (VCCError, KeyError, ValueError, NotImplementedError) as e:
        msg = e.args[0] if isinstance(e, KeyError) and e.args else str(e)
        print(f"vcc: error: {msg}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
