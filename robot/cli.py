"""`vcc robot run`: a concept carried out by the simulated arm in randomized scenarios."""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

from vccjax import runtime

XLA_FLAG = "--xla_cpu_use_fusion_emitters=false"  # batched MJX 14x faster on CPU (docs/robot.md, "MJX on CPU")


def _program(a: argparse.Namespace):
    """The program(s) to carry out; one an arm cannot do is refused here, before MJX."""
    from robot.plan import NOT_ON_A_ROBOT
    from vccjax.machine.instructions import NAMES

    if a.program:
        program = runtime.program_from_arg(a.program)
    else:
        from robot.suite import programs_of

        program = programs_of(a.concept, a.induced)
    for p in program if isinstance(program, list) else [program]:
        for op in p.ops:
            if NAMES[op] in NOT_ON_A_ROBOT:
                raise ValueError(f"{a.concept or 'the program'}: {NAMES[op]} {NOT_ON_A_ROBOT[NAMES[op]]}, "
                                 "not something an arm can do")
    return program


def cmd_run(a: argparse.Namespace) -> int:
    program = _program(a)  # bad input ends here, before JAX and MuJoCo start
    _setup_mjx(a)
    from robot.judge import CAUSES
    from robot.control import RECORD
    from robot.rollout import Bench, scenarios_for

    bench = Bench()
    scenarios = scenarios_for(program, a.scenarios, a.seed)
    verdicts, info, records = bench.run(program, scenarios, keep=a.video is not None)
    for k, v in enumerate(verdicts):
        print(f"scenario {k:3d} (seed {v.seed}): " + ("ok  " if v.success else f"FAIL {v.cause}: ") + v.detail)
    ok = sum(v.success for v in verdicts)
    causes = Counter(v.cause for v in verdicts if not v.success)
    print(f"compile {info['compile_s']:.1f} s, rollout {info['rollout_s']:.1f} s for {info['scenarios']} scenarios "
          f"x {info['simulated_s']:.1f} s simulated, perception and planning {info['prepare_s']:.1f} s")
    print("failures: " + (", ".join(f"{c} {causes[c]}" for c in CAUSES if causes[c]) or "none"))
    if a.video:
        from robot.video import write_video

        k = next((i for i, r in enumerate(records) if r is not None), None)
        if k is None:
            print("no scenario ran: no video")
        else:
            n = write_video(bench.model, scenarios[k], records[k], a.video, RECORD)
            print(f"video: {a.video} ({n} frames, scenario {k})")
    if a.json:
        Path(a.json).write_text(json.dumps({
            "concept": a.concept,
            "program": [p.text() for p in (program if isinstance(program, list) else [program])],
            "scenarios": a.scenarios, "seed": a.seed,
            "success": ok, "timing": info, "verdicts": [v.__dict__ for v in verdicts]}, indent=1))
    print(f"success: {ok} of {len(verdicts)} ({ok / max(1, len(verdicts)):.1%})")
    return 0


def _setup_mjx(a: argparse.Namespace) -> None:
    """Before JAX starts: the XLA flag that makes batched MJX fast on CPU, and one core
    unless --all-cores (batched MJX on both cores of a 2-core CPU hung inside XLA's batched
    Cholesky; pinned to one core it runs as fast: docs/robot.md, "MJX on CPU")."""
    runtime.prepare(xla_flags=[XLA_FLAG], cores=None if a.all_cores else 1)


def cmd_suite(a: argparse.Namespace) -> int:
    _setup_mjx(a)
    from robot.suite import run_suite

    s = run_suite(a.out, a.scenarios, a.seed, induced=a.induced)
    for name, rate in s["per_concept"].items():
        print(f"{rate:7.1%}  {name}")
    print("failures: " + (", ".join(f"{c} {n}" for c, n in s["failures"].items()) or "none"))
    print(f"success: {s['success']} of {s['rollouts']} ({s['success'] / max(1, s['rollouts']):.1%})")
    return 0


def cmd_stress(a: argparse.Namespace) -> int:
    _setup_mjx(a)
    from robot.stress import run_stress

    s = run_stress(a.out, a.rollouts, a.seed)
    print(f"{s['rollouts']} rollouts of {s['concepts']} concepts: {s['rolled_out']} rolled out, "
          f"{s['success']} carried out, wall {s['wall_s']:.0f} s")
    print("failures: " + (", ".join(f"{c} {n}" for c, n in s["failures"].items()) or "none"))
    print(f"non-finite: {s['non_finite']}")
    return 0 if s["non_finite"] == 0 else 1


def add_commands(sub) -> None:
    p = sub.add_parser("robot", help="carry concepts out on a simulated arm (MuJoCo MJX) from a camera image")
    s = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    r = s.add_parser("run", help="roll a concept out in randomized scenarios, batched on MJX",
                     description="Draw randomized scenarios (objects, sizes, colours, positions, distractors, "
                                 "table textures), parse each camera image, run the program on the parsed scene, "
                                 "and carry its hand instructions out with the arm, all scenarios at once. "
                                 "Prints each scenario's outcome and the cause of each failure.")
    r.add_argument("--concept", required=True,
                   help="concept name (its reference program, unless --program); A+B composes two concepts")
    r.add_argument("--program", help="program text or file to run instead of the reference program")
    r.add_argument("--induced", metavar="RUN",
                   help="take the concept's program from this `vcc induce` run folder (default: the reference)")
    r.add_argument("--scenarios", type=int, default=32, help="randomized scenarios (default 32)")
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--video", help="write one rollout as a video (.mp4 or .avi)")
    r.add_argument("--json", help="write the full report here")
    r.add_argument("--all-cores", action="store_true",
                   help="let XLA use every core (on a 2-core CPU this hung at 32 scenarios)")
    r.set_defaults(fn=cmd_run)

    u = s.add_parser("suite", help="the ten-concept benchmark, resumable (one JSON per concept)")
    u.add_argument("--out", required=True, help="results folder (an existing one is resumed)")
    u.add_argument("--induced", metavar="RUN",
                   help="the programs a `vcc induce` run found (its folder) instead of the reference ones")
    u.add_argument("--scenarios", type=int, default=32)
    u.add_argument("--seed", type=int, default=0)
    u.add_argument("--all-cores", action="store_true", help="let XLA use every core")
    u.set_defaults(fn=cmd_suite)

    t = s.add_parser("stress", help="many rollouts of random concepts and scenarios: no NaN, no crash (resumable)")
    t.add_argument("--out", required=True, help="results folder (an existing one is resumed)")
    t.add_argument("--rollouts", type=int, default=1000, help="rollouts, in whole batches of 32 (default 1000)")
    t.add_argument("--seed", type=int, default=7)
    t.add_argument("--all-cores", action="store_true", help="let XLA use every core")
    t.set_defaults(fn=cmd_stress)
