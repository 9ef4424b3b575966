"""`vcc robot run`: a concept carried out by the simulated arm in randomized scenarios."""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

from vccjax import runtime

from robot.suite import XLA_FLAG


def _program(a: argparse.Namespace):
    """The program(s) to carry out; one an arm cannot do is refused here, before MJX."""
    from robot.plan import NOT_ON_A_ROBOT
    from vccjax.machine.instructions import NAMES

    if a.program is not None:
        program = runtime.program_from_arg(a.program)
    else:
        from robot.sources import programs_of

        program = programs_of(a.concept, a.induced)
    for p in program if isinstance(program, list) else [program]:
        for op in p.ops:
            if NAMES[op] in NOT_ON_A_ROBOT:
                raise ValueError(f"{a.concept or 'the program'}: {NAMES[op]} {NOT_ON_A_ROBOT[NAMES[op]]}, "
                                 "not something an arm can do")
    return program


def cmd_run(a: argparse.Namespace) -> int:
    program = _program(a)  # bad input ends here, before JAX and MuJoCo start
    for flag, path, kinds in (("--video", a.video, (".mp4", ".avi")), ("--frames", a.frames, (".png", ".jpg", ".jpeg"))):
        if path and Path(path).suffix.lower() not in kinds:
            raise ValueError(f"{flag} {path}: write {' or '.join(kinds)}")
    if a.scenarios < 1:
        raise ValueError(f"--scenarios {a.scenarios}: must be positive")
    _setup_mjx(a)
    from robot.judge import CAUSES
    from robot.control import RECORD
    from robot.rollout import Bench, scenarios_for

    bench = Bench()
    scenarios = scenarios_for(program, a.scenarios, a.seed)
    verdicts, info, records = bench.run(program, scenarios, keep=bool(a.video or a.frames))
    for k, v in enumerate(verdicts):
        print(f"scenario {k:3d} (seed {v.seed}): " + ("ok  " if v.success else f"FAIL {v.cause}: ") + v.detail)
    ok = sum(v.success for v in verdicts)
    causes = Counter(v.cause for v in verdicts if not v.success)
    print(f"compile {info['compile_s']:.1f} s, rollout {info['rollout_s']:.1f} s for {info['scenarios']} scenarios "
          f"x {info['simulated_s']:.1f} s simulated, perception and planning {info['prepare_s']:.1f} s")
    print("failures: " + (", ".join(f"{c} {causes[c]}" for c in CAUSES if causes[c]) or "none"))
    if a.video or a.frames:
        from robot.video import write_frames, write_video

        k = next((i for i, r in enumerate(records) if r is not None), None)
        if k is None:
            print("no scenario ran: no video")
        if k is not None and a.video:
            n = write_video(bench.model, scenarios[k], records[k], a.video, RECORD)
            print(f"video: {a.video} ({n} frames, scenario {k})")
        if k is not None and a.frames:
            n = write_frames(bench.model, scenarios[k], records[k], a.frames)
            print(f"key frames: {a.frames} ({n}, scenario {k})")
    if a.json:
        from vccjax import files

        files.write_json(a.json, {
            **runtime.provenance(f"vcc robot run --concept {a.concept} --scenarios {a.scenarios} --seed {a.seed}"),
            "concept": a.concept,
            "program": [p.text() for p in (program if isinstance(program, list) else [program])],
            "scenarios": a.scenarios, "seed": a.seed,
            "success": ok, "timing": info, "verdicts": [v.record() for v in verdicts]})
    print(f"success: {ok} of {len(verdicts)} ({ok / max(1, len(verdicts)):.1%})")
    return 0


def _setup_mjx(a: argparse.Namespace) -> None:
    """Before JAX starts: the XLA flag that makes batched MJX fast on CPU, and one core
    unless --all-cores (batched MJX on both cores of a 2-core CPU hung inside XLA's batched
    Cholesky; pinned to one core it runs as fast: docs/robot.md, "MJX on CPU")."""
    runtime.prepare(xla_flags=[XLA_FLAG], cores=None if a.all_cores else 1)


def _suite_programs(a: argparse.Namespace):
    """The suite's programs and concepts, checked before MJX starts."""
    from robot.choice import arm_able, default_choice, not_arm_able
    from robot.sources import Programs, RUN_OF_RECORD
    from robot.suite import TEN

    programs = Programs(a.source or str(RUN_OF_RECORD))
    if a.concepts:
        names = list(TEN) if a.concepts == "ten" else [c.strip() for c in a.concepts.split(",") if c.strip()]
        names = list(dict.fromkeys(names))  # a name given twice runs once
        if not names:
            raise ValueError("--concepts: no concept named")
        for name in names:
            why = not_arm_able(programs.of(name))  # an unknown name is refused here too
            if why:
                raise ValueError(f"--concepts {name}: its program {why}, not something an arm can do")
    else:
        # the choice is of induced concepts: for the reference programs (the comparison) the
        # run of record's, so that both suites run the same concepts
        table = (Programs(str(RUN_OF_RECORD)) if programs.source.kind == "reference" else programs).table
        names = sorted(arm_able(table)) if a.all or programs.source.kind == "library" else \
            default_choice(table, a.count)
        names = [c for c in names if c in programs and not not_arm_able(programs.of(c))]
    if not names:
        raise ValueError(f"--source {programs.source.path or programs.source.kind}: no concept an arm can carry out")
    return programs, names


def _shard(text: str) -> tuple[int, int]:
    try:
        k, n = (int(x) for x in text.split("/"))
    except ValueError:
        raise ValueError(f"--shard {text}: give K/N, as 0/2") from None
    if not 0 <= k < n:
        raise ValueError(f"--shard {text}: K must be in 0..N-1")
    return k, n


def cmd_suite(a: argparse.Namespace) -> int:
    if a.scenarios < 1 or a.count < 1:
        raise ValueError("--scenarios and --count must be positive")
    shard = _shard(a.shard)
    if runtime.on_cluster(a) and shard != (0, 1):
        raise ValueError("--shard splits a suite between processes by hand; --cluster ray does it itself")
    programs, names = _suite_programs(a)  # bad input ends here, before JAX and MuJoCo start
    print(f"{len(names)} concepts from {programs.source.kind} {programs.source.path or ''}, "
          f"{a.scenarios} scenarios each" + (f", shard {a.shard}" if a.shard != "0/1" else ""))
    if a.status:
        from robot.suite import summarise

        if not Path(a.out).is_dir():
            raise ValueError(f"--out {a.out}: no such run folder")
        s = summarise(Path(a.out), programs, names, a.scenarios, a.seed)
    else:
        if a.cluster == "ray":  # batches rolled out on Ray workers, one core each (docs/cluster.md)
            from robot.suite import SuiteWorker, run_suite
            from vccjax.actor_pool import ActorPool

            with ActorPool(SuiteWorker, lambda slot: (slot,), a.workers) as pool:
                s = run_suite(a.out, programs, names, a.scenarios, a.seed, pool=pool)
        else:
            _setup_mjx(a)
            from robot.suite import run_suite

            s = run_suite(a.out, programs, names, a.scenarios, a.seed, shard=shard)
    print("failures: " + (", ".join(f"{c} {n}" for c, n in s["failures"].items()) or "none"))
    p = s["parse"]
    print(f"parse: {p['objects_exact']} of {p['objects']} objects exact, {p['scenes_exact']} of {p['scenes']} scenes")
    print(f"success: {s['success']} of {s['rollouts']} ({s['success'] / max(1, s['rollouts']):.1%}), "
          f"{s['concepts']} of {s['of']} concepts recorded")
    return 0


def cmd_perception(a: argparse.Namespace) -> int:
    if a.scenes < 1:
        raise ValueError(f"--scenes {a.scenes}: must be positive")
    out = Path(a.out)
    if out.suffix != ".json":
        raise ValueError(f"--out {a.out}: write a .json file")
    runtime.prepare(cores=1)
    from tqdm import tqdm

    from robot.perception_sweep import CONDITIONS, sweep

    bar = tqdm(total=a.scenes * len(CONDITIONS), desc="camera parse", unit="scene")
    table = sweep(a.scenes, a.seed, progress=bar.update)
    bar.close()
    for name, t in table.items():
        print(f"{name:32s} objects exact {t['objects_exact']} of {t['objects']} "
              f"({t['objects_exact'] / max(1, t['objects']):.2%}), scenes exact {t['scenes_exact']} of {t['scenes']}, "
              f"largest centre error {t['largest_centre_error_m'] * 1000:.1f} mm")
    record = {**runtime.provenance(f"vcc robot perception --scenes {a.scenes} --seed {a.seed} --out {a.out}"),
              "benchmark": "robot-perception", "scenes": a.scenes, "seed": a.seed, "conditions": table}
    from robot.suite import write_record

    write_record(out, record)
    print(f"-> {out}")
    return 0


def cmd_stress(a: argparse.Namespace) -> int:
    from robot.sources import Programs, RUN_OF_RECORD

    programs = Programs(a.source or str(RUN_OF_RECORD))
    _setup_mjx(a)
    from robot.stress import run_stress

    s = run_stress(a.out, programs, a.rollouts, a.seed)
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
    r.add_argument("--scenarios", type=runtime.count(1, 4096), default=32, help="randomized scenarios (default 32)")
    r.add_argument("--seed", type=runtime.count(0), default=0)
    r.add_argument("--video", type=runtime.out_file(".mp4", ".avi"), help="write one rollout as a video (.mp4 or .avi)")
    r.add_argument("--frames", type=runtime.out_file(".png", ".jpg", ".jpeg"),
                   help="write that rollout's key frames side by side as a picture (.png or .jpg)")
    r.add_argument("--json", type=runtime.out_file(".json"), help="write the full report here")
    r.add_argument("--all-cores", action="store_true",
                   help="let XLA use every core (on a 2-core CPU this hung at 32 scenarios)")
    r.set_defaults(fn=cmd_run)

    u = s.add_parser("suite", help="learned concepts on the arm, judged against the true scene (resumable)",
                     description="Carry out concepts from their learned programs (default: those the run of "
                                 "record induced) in randomized scenarios; one JSON per concept with a record per "
                                 "scenario. Default choice: 150 arm-able concepts stratified by program length "
                                 "(docs/robot.md).")
    u.add_argument("--out", required=True, type=runtime.out_folder, help="results folder (an existing one is resumed)")
    u.add_argument("--source", metavar="RUN|reference|library",
                   help="where programs come from: a `vcc induce` run folder (default: the run of record), "
                        "the shipped reference programs, or the user's library of learned concepts")
    u.add_argument("--concepts", type=runtime.name_list,
                   help="comma-separated names (A+B composes), or 'ten' for the first ten-concept suite")
    u.add_argument("--all", action="store_true", help="every arm-able concept of the source")
    u.add_argument("--count", type=runtime.count(1, 10**4), default=150,
                   help="concepts in the default stratified choice (150)")
    u.add_argument("--scenarios", type=runtime.count(1, 4096), default=8,
                   help="randomized scenarios per concept (default 8)")
    u.add_argument("--seed", type=runtime.count(0), default=0)
    u.add_argument("--shard", default="0/1", metavar="K/N",
                   help="run only every N-th concept from the K-th: N processes on one folder, one core each")
    u.add_argument("--status", action="store_true",
                   help="only summarise what the folder holds (writes summary.json), running no rollout")
    u.add_argument("--all-cores", action="store_true", help="let XLA use every core")
    runtime.cluster_flags(u, "roll the batches out on Ray workers, one core each; this process writes the records")
    u.set_defaults(fn=cmd_suite)

    c = s.add_parser("perception", help="the arm camera's parse against the true tables, nominal and harder",
                     description="Render the suite's scenes from the top camera under nominal light, dimmer and "
                                 "brighter light, and with the camera a few millimetres and degrees off its "
                                 "calibration; parse each and check it against the objects truly on the table.")
    c.add_argument("--out", required=True, type=runtime.out_file(".json"), help="result JSON")
    c.add_argument("--scenes", type=runtime.count(1, 10**5), default=200, help="scenes per condition (default 200)")
    c.add_argument("--seed", type=runtime.count(0), default=0)
    c.set_defaults(fn=cmd_perception)

    t = s.add_parser("stress", help="many rollouts of random concepts and scenarios: no NaN, no crash (resumable)")
    t.add_argument("--out", required=True, type=runtime.out_folder, help="results folder (an existing one is resumed)")
    t.add_argument("--rollouts", type=runtime.count(1, 10**6), default=1000,
                   help="rollouts, in whole batches of 32 (default 1000)")
    t.add_argument("--seed", type=runtime.count(0), default=7)
    t.add_argument("--source", metavar="RUN|reference|library",
                   help="where programs come from (default: the run of record's learned programs)")
    t.add_argument("--all-cores", action="store_true", help="let XLA use every core")
    t.set_defaults(fn=cmd_stress)
