"""Training data for the argument predictor: short programs and their examples.

The paper enumerates every valid program up to length 6 (scene_parse included), keeps
those that change their inputs and in which every instruction with its argument is
indispensable, and makes 10 examples of each. Enumerating is some 10^7 programs here,
most of them thrown away by the filters, so we draw programs and apply the filters:
- valid: a program grows on 3 input scenes (drawn as for the concepts' training
  split, a pointer in all or none), one (instruction, argument) step at a time, each
  drawn uniformly among the steps that run on all three, keep loop syntax and change
  what the machine holds, up to a length drawn uniformly in 3..6 (as the paper; 8 did not
  recall more concepts: docs/argpred.md), then is cut after its last
  step that changed a scene; its 10 examples are drawn afresh as for a concept
  (`examples.make_pairs`): inputs on which it runs;
- informative: every example's output differs from its input;
- indispensable: deleting any one instruction (but scene_parse) makes it fail or
  changes some output; a deletion that breaks loop syntax counts as indispensable.
  A drawn program with dispensable instructions is not thrown away: they are deleted
  one at a time (outputs unchanged) until every one left is indispensable.
No concept of the 546 is used. Programs are drawn in shards, each seeded by (seed,
shard), and written as they finish, so a build resumes and gives the same bytes.

A second kind of folder (`kind="carry"`) holds programs no draw of six instructions
reaches: carry one selected object onto another one (two attends, 10 instructions),
the elementary "put A at B". Its selectors are drawn (a shape or colour filter, a
fixation, the pointer or none; the target by a filter), then the same filters apply.
Without them the predictor never sees a filter whose object stays where it is
(docs/argpred.md).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from argpred.features import MAX_OBJECTS, scene_cells
from vccjax import files
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.errors import DataFileError, ProgramSyntaxError, SceneError
from vccjax.world.pairs import TRAIN, ExampleError, distinguishes, make_pairs
from vccjax.world.scenes import random_scene
from vccjax.machine.instructions import NAMES, OP, arg_domain
from vccjax.machine.program import Program, check_loop_syntax
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, scenes_match

PREDICTED: tuple[str, ...] = ("set_shape_attn", "set_color_attn", "fill_color")
LABELS: tuple[tuple[str, str], ...] = tuple((f, v) for f in PREDICTED for v in arg_domain(f))
FORMAT, VERSION = "vccjax-argpred-data", 1
SHARD = 100  # programs per shard file
KINDS = ("drawn", "carry", "loop")
LENGTHS = (3, 6)  # scene_parse and one instruction change no scene; 6 as the paper (8: docs/argpred.md)
_DRAWABLE = tuple(op for op in range(len(NAMES)) if op != OP["scene_parse"])


def labels_of(program: Program) -> np.ndarray:
    """(13,) 1 for each (function, argument) the program uses."""
    used = {(NAMES[o], arg_domain(NAMES[o])[a]) for o, a in zip(program.ops, program.args) if NAMES[o] in PREDICTED}
    return np.array([lab in used for lab in LABELS], np.int8)


def grow(rng: np.random.Generator, scenes: list[Scene], length: int,
         prefix: Program | None = None) -> Program | None:
    """A program of at most `length` instructions that runs on every scene: scene_parse
    (or `prefix`), then at each step an (instruction, argument) drawn uniformly among
    those that run on every scene and change what some machine holds; cut after the
    last step that changed a scene (later ones could only be dispensable). None if no
    step after the prefix did."""
    prefix = prefix or Program((OP["scene_parse"],), (0,))
    machines = [RefMachine(s, validate=False) for s in scenes]
    for m in machines:
        for op, arg in zip(prefix.ops, prefix.args):
            m.step(op, arg)
    ops, args, ends = list(prefix.ops), list(prefix.args), []
    steps = [(o, a) for o in _DRAWABLE for a in range(max(1, len(arg_domain(NAMES[o]))))]
    while len(ops) < length:
        for k in rng.permutation(len(steps)):
            op, arg = steps[k]
            try:
                check_loop_syntax(Program((*ops, op), (*args, arg)), complete=False)
            except ProgramSyntaxError:
                continue
            trial = [m.clone() for m in machines]
            for m in trial:
                m.step(op, arg)
            if any(m.failed for m in trial):
                continue
            if NAMES[op] not in ("loop_start", "loop_end") and not any(m.control.in_loop for m in trial) and all(
                    _signature(a) == _signature(b) for a, b in zip(machines, trial)):
                continue  # changes nothing the machine shows: it could only be dispensable
            if any(_scene(a) != _scene(b) for a, b in zip(machines, trial)):
                ends.append(len(ops) + 1)
            machines, ops, args = trial, [*ops, op], [*args, arg]
            break
        else:
            break  # no step runs here
    for end in reversed(ends):
        program = Program(tuple(ops[:end]), tuple(args[:end]))
        try:
            check_loop_syntax(program)
        except ProgramSyntaxError:
            continue
        return program
    return None


def _scene(m: RefMachine) -> tuple:
    """Each of the scene's objects: centre, colour, alive."""
    b = m.blackboard
    return tuple((m.centre(i), b.color[i], b.alive[i]) for i in range(len(m.scene.objects)))


def _signature(m: RefMachine) -> tuple:
    """What a step can change that a later step can read (the fixation history aside)."""
    a, b = m.attention, m.blackboard
    return (_scene(m), b.imagined_kind, b.imagined_position if b.imagined_kind >= 0 else None, m.fovea.position,
            m.hand.position, m.hand.held, a.shape_filter, a.color_filter, tuple(a.attended_list), a.stale, a.cursor,
            a.attended)


def _deletions(program: Program):
    """The program without each one instruction (but scene_parse), where loop syntax holds."""
    for i in range(1, len(program)):
        rival = Program(program.ops[:i] + program.ops[i + 1 :], program.args[:i] + program.args[i + 1 :])
        try:
            check_loop_syntax(rival)
        except ProgramSyntaxError:
            continue
        yield rival


def indispensable(program: Program, pairs) -> bool:
    """Deleting any one instruction (but scene_parse) fails or changes some output."""
    return all(any(distinguishes(rival, a, b) for a, b in pairs) for rival in _deletions(program))


def minimal(program: Program, pairs) -> Program:
    """Delete dispensable instructions, last first, until every one left is
    indispensable; the outputs on `pairs` stay the same at every deletion."""
    while True:
        for rival in reversed(list(_deletions(program))):
            if not any(distinguishes(rival, a, b) for a, b in pairs):
                program = rival
                break
        else:
            return program


def scene_pool(rng: np.random.Generator, size: int = 200) -> dict[bool, list[Scene]]:
    """Inputs to grow programs on, with and without a pointer (drawing a scene costs
    about 2 ms: a pool is drawn once per shard)."""
    pool: dict[bool, list[Scene]] = {False: [], True: []}
    for pointer in (False, True):
        while len(pool[pointer]) < size:
            try:
                pool[pointer].append(random_scene(rng, TRAIN.objects, widths=TRAIN.widths, pointer=pointer))
            except SceneError:
                continue
    return pool


def kept_program(rng: np.random.Generator, pool: dict[bool, list[Scene]], probes: int = 3, max_tries: int = 60,
                 joined: float = 0.0) -> tuple[Program, list[tuple[Scene, Scene]]]:
    """Draw until a program passes the filters; (program, its 10 pairs). A program grows
    on `probes` pool scenes (half the draws with a pointer) and must change one of them;
    its 10 examples are then drawn afresh (`examples.make_pairs`: it runs on each input
    and changes it), and dispensable instructions are deleted (`minimal`)."""
    while True:
        scenes = pool[bool(rng.integers(2))]
        probe = [scenes[int(k)] for k in rng.choice(len(scenes), probes, replace=False)]
        program = grow(rng, probe, int(rng.integers(LENGTHS[0], LENGTHS[1] + 1)))
        if program is None:
            continue
        if joined and rng.random() < joined:  # a second part after reset_attn, as the concepts' "A and B"
            first = Program((*program.ops, OP["reset_attn"]), (*program.args, 0))
            program = grow(rng, probe, len(first) + int(rng.integers(LENGTHS[0] - 1, LENGTHS[1])), prefix=first)
            if program is None:
                continue
        outs = [RefMachine(s, validate=False).run(program).output_scene() for s in probe]
        if all(scenes_match(o, s, DEFAULT_CONFIG.tau) for o, s in zip(outs, probe)):
            continue  # changes nothing it was grown on
        try:
            pairs = make_pairs(program, TRAIN, rng, jitter=None, max_tries=max_tries)
        except ExampleError:
            continue
        program = minimal(program, pairs)
        if len(program) >= LENGTHS[0]:
            return program, pairs


def _selector(rng: np.random.Generator, filters_only: bool = False) -> list[tuple[str, str | None]]:
    """How a carry picks an object: a shape or colour filter, a fixation, the pointer, or
    none (the first attended object)."""
    k = int(rng.integers(2 if filters_only else 5))
    if k < 2:
        f = PREDICTED[k]
        return [(f, arg_domain(f)[int(rng.integers(len(arg_domain(f))))])]
    if k == 2:
        return [("fixate", arg_domain("fixate")[int(rng.integers(len(arg_domain("fixate"))))])]
    return [("fixate_pointer", None)] if k == 3 else []


def carry_program(rng: np.random.Generator, fill: float = 0.25) -> Program:
    """Pick an object, carry it onto another one picked by a filter, release it (and,
    `fill` of the time, recolour what is attended then)."""
    steps = [("scene_parse", None), *_selector(rng), ("top_down_attend", None),
             ("move_hand_to_attended_object", None), ("grab_object", None), ("reset_attn", None),
             *_selector(rng, filters_only=True), ("top_down_attend", None),
             ("move_hand_to_attended_object", None), ("release_object", None)]
    if rng.random() < fill:
        steps.append(("fill_color", arg_domain("fill_color")[int(rng.integers(len(arg_domain("fill_color"))))]))
    return Program(tuple(OP[n] for n, _ in steps), tuple(0 if a is None else arg_domain(n).index(a) for n, a in steps))


_MOVES = ("move_hand_left", "move_hand_right", "move_hand_up", "move_hand_down")


def loop_program(rng: np.random.Generator) -> Program:
    """Do one thing to every attended object: an optional selection (a shape or colour
    filter, both, or a fixation), then a loop whose body recolours the object, moves it
    one hand step or two at a right angle, or both (docs/vcc.md section 5)."""
    k = int(rng.integers(5))  # none, shape, colour, both filters, a fixation
    pick = ([] if k == 0 else _selector(rng, filters_only=True) if k < 3 else
            [*_one_filter(rng, 0), *_one_filter(rng, 1)] if k == 3 else
            [("fixate", arg_domain("fixate")[int(rng.integers(len(arg_domain("fixate"))))])])
    colour = ("fill_color", arg_domain("fill_color")[int(rng.integers(len(arg_domain("fill_color"))))])
    kind = int(rng.integers(3))  # recolour, move, both
    first = int(rng.integers(len(_MOVES)))
    turns = [first] + ([(first // 2 * 2 + 2 + int(rng.integers(2))) % 4] if rng.random() < 0.5 else [])
    move = [("move_hand_to_attended_object", None), ("grab_object", None), *[(_MOVES[d], None) for d in turns],
            ("release_object", None)]
    body = [colour] if kind == 0 else move if kind == 1 else [colour, *move]
    steps = [("scene_parse", None), *pick, ("loop_start", None), ("top_down_attend", None), *body,
             ("next_object", None), ("loop_end", None)]
    return Program(tuple(OP[n] for n, _ in steps), tuple(0 if a is None else arg_domain(n).index(a) for n, a in steps))


def _one_filter(rng: np.random.Generator, which: int) -> list[tuple[str, str]]:
    f = PREDICTED[which]
    return [(f, arg_domain(f)[int(rng.integers(len(arg_domain(f))))])]


def kept_carry(rng: np.random.Generator, max_tries: int = 60,
               draw: Callable[[np.random.Generator], Program] = carry_program) -> tuple[Program, list[tuple[Scene, Scene]]]:
    """A program of `draw` (carry or loop) whose 10 examples can be drawn, made minimal
    (as `kept_program`)."""
    while True:
        program = draw(rng)
        try:
            pairs = make_pairs(program, TRAIN, rng, jitter=None, max_tries=max_tries)
        except ExampleError:
            continue
        return minimal(program, pairs), pairs


def build_shard(seed: int, shard: int, size: int = SHARD, joined: float = 0.0,
                kind: str = "drawn") -> dict[str, np.ndarray]:
    """`joined`: the share of programs drawn as two parts joined by reset_attn (0 keeps
    the draws of the shipped weights' data byte for byte); `kind="carry"`: carry
    programs (`carry_program`) instead, `kind="loop"`: loop programs (`loop_program`)."""
    if kind == "carry":
        key = [seed, shard, 0xCA77]
    elif kind == "loop":
        key = [seed, shard, 0x100F]
    else:
        key = [seed, shard, 0xA59] + ([int(round(joined * 1000))] if joined else [])
    rng = np.random.default_rng(key)
    progs, ins, outs = [], [], []
    seen: set = set()
    pool = scene_pool(rng) if kind == "drawn" else {}
    while len(progs) < size:
        program, pairs = (kept_program(rng, pool, joined=joined) if kind == "drawn" else
                          kept_carry(rng, draw=loop_program if kind == "loop" else carry_program))
        if (program.ops, program.args) in seen:
            continue
        seen.add((program.ops, program.args))
        progs.append(program)
        ins.append(np.stack([scene_cells(a) for a, _ in pairs]))
        outs.append(np.stack([scene_cells(b) for _, b in pairs]))
    text = "\n".join(p.text() for p in progs)
    return {
        "format_version": np.array([VERSION], np.int32), "seed": np.array([seed, shard], np.int64),
        "programs": np.frombuffer(text.encode(), np.uint8),
        "inputs": np.stack(ins), "outputs": np.stack(outs),  # (P, 10, 9, 4) int8 cells
        "labels": np.stack([labels_of(p) for p in progs]),
        **({"joined": np.array([joined])} if joined else {}),
        **({"kind": np.frombuffer(kind.encode(), np.uint8)} if kind != "drawn" else {}),
    }


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def build(out: str | Path, programs: int, seed: int = 0, workers: int = 1,
          progress: bool = True, joined: float = 0.0, kind: str = "drawn") -> dict:
    """Build (or resume) `programs` training programs of `kind` under `out`, in shards of
    100 (the last one holds the rest). A folder built with another seed, kind or share
    of joined programs is refused, not rebuilt."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from tqdm import tqdm

    if kind not in KINDS:
        raise ValueError(f"unknown kind of training data {kind!r} (one of {', '.join(KINDS)})")
    if kind != "drawn" and joined:
        raise ValueError(f"{kind} programs are not joined; use joined=0 for kind {kind!r}")
    out = Path(out)
    files.hold(out, "data folder")  # one builder at a time
    n = -(-programs // SHARD)
    sizes = [min(SHARD, programs - k * SHARD) for k in range(n)]
    if (out / "manifest.json").exists():
        try:
            old = json.loads((out / "manifest.json").read_text())
            mine = (old["seed"], old.get("joined", 0.0), old.get("kind", "drawn"))
        except (ValueError, KeyError, TypeError) as e:
            raise DataFileError(f"{out / 'manifest.json'}: not a manifest of this data ({e})") from None
        if mine != (seed, joined, kind):
            raise DataFileError(f"{out}: built with seed {mine[0]}, joined {mine[1]}, kind {mine[2]}; asked for seed "
                                f"{seed}, joined {joined}, kind {kind}; use those or another folder")
    jobs = [(out, seed, k, joined, kind, sizes[k]) for k in range(n)]
    todo = [j for j in jobs if not _valid_shard(*j)]
    bar = tqdm(total=n, initial=n - len(todo), desc=f"argpred data ({kind})", unit="shard", disable=not progress)
    if workers > 1 and len(todo) > 1:
        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
            for _ in pool.map(_write_shard, todo):
                bar.update()
    else:
        for job in todo:
            _write_shard(job)
            bar.update()
    bar.close()
    manifest = {"format": FORMAT, "version": VERSION, "seed": seed, "joined": joined, "shard": SHARD,
                "lengths": list(LENGTHS),
                "labels": [list(x) for x in LABELS], "max_objects": MAX_OBJECTS,
                "shards": {f"shard{k:04d}.npz": _sha(out / f"shard{k:04d}.npz") for k in range(n)},
                **({"kind": kind, "programs": programs} if kind != "drawn" else {})}
    files.write_json(out / "manifest.json", manifest)
    return manifest


def built(folder: str | Path) -> dict | None:
    """What a built folder's manifest says: programs, seed, joined share and kind (None
    when there is none), so that training on an existing folder keeps all of it as it is."""
    try:
        manifest = json.loads((Path(folder) / "manifest.json").read_text())
        return {"programs": int(manifest.get("programs", len(manifest["shards"]) * int(manifest["shard"]))),
                "seed": int(manifest["seed"]), "joined": float(manifest.get("joined", 0.0)),
                "kind": str(manifest.get("kind", "drawn"))}
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _write_shard(job) -> None:
    out, seed, k, joined, kind, size = job
    arrays = build_shard(seed, k, size=size, joined=joined, kind=kind)
    with files.whole(out / f"shard{k:04d}.npz") as tmp:  # whole or not at all
        np.savez_compressed(tmp, **arrays)


def _valid_shard(out: Path, seed: int, k: int, joined: float = 0.0, kind: str = "drawn", size: int = SHARD) -> bool:
    path = out / f"shard{k:04d}.npz"
    if not path.exists():
        return False
    try:
        with np.load(path, allow_pickle=False) as z:
            share = float(z["joined"][0]) if "joined" in z.files else 0.0
            made = bytes(z["kind"]).decode() if "kind" in z.files else "drawn"
            return (int(z["format_version"][0]) == VERSION and z["seed"].tolist() == [seed, k] and share == joined
                    and made == kind and len(z["labels"]) == size)
    except (OSError, ValueError, KeyError):
        return False  # cut or foreign: rebuild it


def load(folder: str | Path, log: Callable[[str], None] | None = None) -> dict[str, np.ndarray]:
    """All shards of a built folder, verified against its manifest."""
    folder = Path(folder)
    path = folder / "manifest.json"
    try:
        manifest = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise DataFileError(f"{path}: cannot read ({e}); build with `vcc argpred data`") from None
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT or manifest.get("version") != VERSION:
        raise DataFileError(f"{path}: not a {FORMAT} v{VERSION} manifest")
    parts: dict[str, list] = {"inputs": [], "outputs": [], "labels": [], "programs": []}
    for name, sha in sorted(manifest["shards"].items()):
        p = folder / name
        if not p.exists() or _sha(p) != sha:
            raise DataFileError(f"{p}: missing, or its sha256 differs from the manifest")
        with np.load(p, allow_pickle=False) as z:
            for key in ("inputs", "outputs", "labels"):
                parts[key].append(z[key])
            parts["programs"] += bytes(z["programs"]).decode().split("\n")
    return {"inputs": np.concatenate(parts["inputs"]), "outputs": np.concatenate(parts["outputs"]),
            "labels": np.concatenate(parts["labels"]), "programs": np.array(parts["programs"])}
