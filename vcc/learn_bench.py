"""`vcc bench learn`: new concepts (not among the 546) learned from their pairs alone,
with the shipped library against from scratch, and the questions asked back.

Rows, one JSON line each in `RUN/results.jsonl` (written as soon as known; a rerun
resumes and refuses a folder made with other settings, programs or examples):
- `learn`: each concept x examples (10 and 3 by default) x start (library, uniform),
  predicted arguments, the budget: found, and right on all 50 test pairs; what no whole
  program within the budget fits is then learned in parts from the same start, as
  `vcc learn` does (`parts`: how many, 0 when whole);
- `ask`: each concept from 2 examples with the library, as `vcc learn` runs: whether
  the first program found is right, whether the pairs were reported ambiguous, and,
  when they were, whether one answered query settles it (the query's input with the
  output the concept's own program gives there, added as a third pair, and learned again
  with the programs the question was about, as `vcc learn` reruns in the same folder).
The concept's program is read only to make its examples and to answer the query, as a
user would; never by the search.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import time
from pathlib import Path

from vccjax.errors import DataFileError, read_json
from vccjax import runtime
from vccjax.records import append_line

STARTS = ("library", "uniform")
# 2: the answered question is learned again with the programs it was about, and fresh
# scenes may hold one object more than the examples; 3: what no whole program fits is
# learned in parts (`search.parts`); 4: of the joins of parts that fit, the most probable,
# and what the library's search misses is tried from a uniform start over a tenth of the
# budget before the parts (`search.learn.from_uniform`); 5: when no join of parts fits,
# graded first parts continued from the machine state they leave (`search.parts.continued`);
# 6: fill_color's arguments from the colours objects gain (`argpred.gained`), not the network;
# 7: filter values the objects acted on rule out dropped (`argpred.acted`); 8: first parts
# continued once more with a fixation added (`search.parts.remembering`); 9: filter values
# the pairs point in raised (`argpred.acted`, `--filters acted+raised`); 10: searches for a
# first part of more progress than those kept (`search.parts.first_parts`); 11: the first
# program failing where a rival runs is ambiguity too (`search.ambiguity`), and the program's
# each-or-one variants join the rivals (`search.each_or_one`)
# (a run of another protocol is refused)
PROTOCOL = 11
# What every results line must hold (the key of `_key`, and whether it was found).
RECORD_SCHEMA = {"kind": (str,), "concept": (str,), "examples": (int,), "start": (str,), "found": (bool,)}


def _key(r: dict) -> tuple:
    return r["kind"], r["concept"], r["examples"], r["start"]


def _open_run(folder: Path, meta: dict) -> list[dict]:
    """The records of an earlier session of this run (a last line cut by an interrupt is
    dropped); a folder made with other settings is refused."""
    from vccjax import files
    from vccjax.records import drop_cut_tail, read_jsonl

    files.check_writable(folder, "run", folder=True)
    files.hold(folder)  # one writer per run folder
    path = folder / "run.json"
    if path.exists():
        old = read_json(path, DataFileError, "no run.json")
        if old != meta:
            raise DataFileError(f"{path}: this folder holds a run with other settings, programs or examples; "
                                "use another --run or the same settings to resume")
    else:
        files.write_json(path, meta)
    results = folder / "results.jsonl"
    records = read_jsonl(results, RECORD_SCHEMA)
    drop_cut_tail(results)  # never a rewrite: a kill then would lose the run
    return records


def cmd_bench_learn(a: argparse.Namespace) -> int:
    from search.explore import Explorer
    from search.induce import generalization
    from search.learn import LearnSettings, chain_for, from_uniform, in_parts, learn, model_for
    from search.task import Task
    from vccjax.machine.config import DEFAULT_CONFIG
    from vccjax.world.concepts import read_programs
    from vccjax.world.dataset import build_dataset, Dataset, rival_warnings

    examples = sorted({int(k) for k in a.examples.split(",")}, reverse=True)
    programs = read_programs(a.programs)
    runtime.prepare()
    run = Path(a.run)
    asking = LearnSettings(budget=a.budget)
    head = {"protocol": PROTOCOL, "budget": a.budget, "examples": examples, "ask_examples": a.ask_examples,
            "ask_settings": dataclasses.asdict(asking),
            "programs_sha256": hashlib.sha256(Path(a.programs).read_bytes()).hexdigest()}
    if (run / "run.json").exists():  # a run of other settings is refused before examples are built into it
        old = read_json(run / "run.json", DataFileError, "missing")
        if not isinstance(old, dict) or any(old.get(k) != v for k, v in head.items()):
            raise DataFileError(f"{run / 'run.json'}: this folder holds a run with other settings or programs; "
                                "use another --run or the same settings to resume")
    data = Path(a.dataset) if a.dataset else run / "examples"
    for line in rival_warnings(build_dataset(data, seed=0, programs=programs, progress=not a.quiet)):
        print(line)
    ds = Dataset(data)
    failed = [c for c in programs if c not in ds.manifest["concepts"]]
    if failed:
        raise DataFileError(f"{data}: no examples could be made for {', '.join(failed)}")
    names = list(programs)
    meta = {**head, "examples_sha256": {c: ds.sha256(c) for c in names}}
    records = _open_run(run, meta)
    done = {_key(r) for r in records}
    tau = DEFAULT_CONFIG.tau
    explorer = Explorer(width=a.width)
    starts = {s: model_for("shipped" if s == "library" else "uniform") for s in STARTS}

    def write(record: dict) -> None:
        records.append(record)
        append_line(run / "results.jsonl", record)

    # learning: every concept, examples and start, in lockstep (rivals are not needed here)
    for k in examples:
        for start in STARTS:
            todo = [c for c in names if ("learn", c, k, start) not in done]
            if not todo:
                continue
            print(f"learning {len(todo)} concepts from {k} examples, start: {start}")
            settings = LearnSettings(budget=a.budget, rival_budget=0)
            jobs = [(chain_for(ds.pairs(c, "train")[:k], settings, starts[start])[0],
                     Task.from_pairs(ds.pairs(c, "train")[:k])) for c in todo]

            def record(c: str, r, parts: tuple, k=k, start=start, uniform: bool = False) -> None:
                right = generalization(r.program, ds.pairs(c, "test"), tau) if r.found else 0
                write({"kind": "learn", "concept": c, "examples": k, "start": start, "found": r.found,
                       "right": bool(r.found and right == len(ds.pairs(c, "test"))), "test_right": right,
                       "program": r.program.text() if r.found else None, "rank": r.rank, "parts": len(parts),
                       "programs": r.programs, "seconds": round(r.seconds, 3), "from_uniform": uniform})
                if not a.quiet:
                    print(f"  {c}: {'found' if r.found else 'not found'}"
                          + (" from a uniform start" if uniform else "")
                          + (f" in {len(parts)} parts" if parts else "")
                          + (f", {right}/{len(ds.pairs(c, 'test'))} test pairs" if r.found else ""))

            unfound = []
            explorer.search_many(jobs, a.budget, lambda j, r, todo=todo: (
                record(todo[j], r, ()) if r.found else unfound.append((todo[j], r))))
            for c, r in unfound:  # one at a time: each part's search is a search of its own
                r, uniform = from_uniform(r, ds.pairs(c, "train")[:k], settings, explorer, starts[start])
                record(c, *in_parts(r, ds.pairs(c, "train")[:k], settings, explorer, starts[start]),
                       uniform=uniform is not None)
    # asking back: two examples, the library, rivals on (as vcc learn runs)
    k = a.ask_examples
    for c in names:
        if ("ask", c, k, "library") in done:
            continue
        settings = asking
        pairs = ds.pairs(c, "train")[:k]
        first = learn(pairs, settings, explorer)
        test = ds.pairs(c, "test")
        rec = {"kind": "ask", "concept": c, "examples": k, "start": "library", "found": first.found,
               "right": bool(first.found and generalization(first.program, test, tau) == len(test)),
               "ambiguous": first.ambiguous, "rivals": len(first.rivals()), "settled": None,
               "program": first.program.text() if first.found else None}
        if first.ambiguous:
            from vccjax.machine.reference import RefMachine

            q = first.query_scene
            m = RefMachine(q).run(programs[c])
            if m.failed:
                rec["settled"], rec["answer"] = False, "the concept's program fails on the query"
            else:
                asked = [first.program] + [p for p, *_ in first.rivals()]  # as a `vcc learn` rerun reads them
                again = learn([*pairs, (q, m.output_scene())], settings, explorer, asked=asked)
                rec["settled"] = bool(again.found and generalization(again.program, test, tau) == len(test))
                rec["settled_program"] = again.program.text() if again.found else None
                rec["from_question"] = bool(again.found and again.program in asked)
                rec["still_ambiguous"] = again.ambiguous
        write(rec)
        if not a.quiet:
            print(f"  {c}: first {'right' if rec['right'] else 'wrong'}, "
                  f"{'ambiguous' if rec['ambiguous'] else 'not ambiguous'}"
                  + (f", settled: {rec['settled']}" if rec["ambiguous"] else ""))
    summary = summarise(records, names, examples, k)
    timing = learn_timing(a, ds, names, programs) if a.timing else None
    _write_summary(a, summary, timing, run)
    return 0


def summarise(records: list[dict], names: list[str], examples: list[int], ask: int) -> dict:
    table = {}
    for k in examples:
        for s in STARTS:
            rows = [r for r in records if r["kind"] == "learn" and r["examples"] == k and r["start"] == s]
            table[f"{s}, {k} examples"] = {"concepts": len(rows), "found": sum(r["found"] for r in rows),
                                           "right": sum(r["right"] for r in rows),
                                           "in_parts": sum(r["found"] and r.get("parts", 0) > 0 for r in rows),
                                           "right_in_parts": sum(r["right"] and r.get("parts", 0) > 0 for r in rows),
                                           "from_uniform": sum(r["found"] and bool(r.get("from_uniform")) for r in rows),
                                           "right_from_uniform": sum(r["right"] and bool(r.get("from_uniform"))
                                                                    for r in rows)}
    asks = [r for r in records if r["kind"] == "ask" and r["examples"] == ask]
    wrong = [r for r in asks if r["found"] and not r["right"]]
    right = [r for r in asks if r["right"]]
    flagged = [r for r in wrong if r["ambiguous"]]
    return {"concepts": len(names), "learn": table, "ask": {
        "examples": ask, "concepts": len(asks), "found": sum(r["found"] for r in asks),
        "first_right": len(right), "first_wrong": len(wrong),
        "wrong_reported_ambiguous": len(flagged),
        "wrong_settled_by_one_query": sum(bool(r["settled"]) for r in flagged),
        "right_reported_ambiguous": sum(r["ambiguous"] for r in right),
    }}


def learn_timing(a: argparse.Namespace, ds, names: list[str], programs: dict) -> dict:
    """`vcc learn` on a short concept (at most 8 instructions) from 5 JSON pairs, as a
    user runs it: a fresh process with an empty compile cache (cold), then again (warm)."""
    import os
    import subprocess
    import sys
    import tempfile

    short = next(c for c in names if len(programs[c]) <= 8)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        folder = tmp / "examples"
        folder.mkdir()
        for i, (x, y) in enumerate(ds.pairs(short, "train")[:5]):
            x.save(folder / f"{i}_in.json")
            y.save(folder / f"{i}_out.json")
        env = dict(os.environ, VCCJAX_CACHE=str(tmp / "cache"))
        walls = []
        for _ in ("cold", "warm"):
            t0 = time.perf_counter()
            done = subprocess.run([sys.executable, "-m", "vcc", "learn", str(folder), "--out", str(tmp / "out"),
                                   "--quiet"], env=env, capture_output=True, text=True)
            walls.append(round(time.perf_counter() - t0, 1))
            if done.returncode != 0:
                raise RuntimeError(f"vcc learn failed while timing: {done.stderr.strip()[-300:]}")
        learned = json.loads((tmp / "out" / "concept.json").read_text())
    return {"concept": short, "instructions": len(programs[short]), "pairs": 5, "cold_seconds": walls[0],
            "warm_seconds": walls[1], "program": learned["program"], "cores": os.cpu_count()}


def _write_summary(a: argparse.Namespace, summary: dict, timing: dict | None, run: Path) -> None:
    from vcc.bench import stamp

    from vccjax import files

    report = {**stamp(a, "learn"), "benchmark": "learn", "run": str(run), **summary, "timing": timing}
    files.write_json(a.out, report)
    print(f"{'':28}{'found':>8}{'right':>8}{'in parts':>10}   (of {summary['concepts']} new concepts; right: all 50 "
          "test pairs; in parts: of the right, learned in parts)")
    for label, row in summary["learn"].items():
        print(f"{label:28}{row['found']:>8}{row['right']:>8}{row['right_in_parts']:>10}")
    s = summary["ask"]
    print(f"from {s['examples']} examples: first program right {s['first_right']}, wrong {s['first_wrong']}; "
          f"of the wrong, reported ambiguous {s['wrong_reported_ambiguous']}, settled by one answered query "
          f"{s['wrong_settled_by_one_query']}; false alarms (right but reported ambiguous) "
          f"{s['right_reported_ambiguous']}")
    if timing:
        print(f"vcc learn {timing['concept']} ({timing['instructions']} instructions, 5 pairs): "
              f"cold {timing['cold_seconds']} s, warm {timing['warm_seconds']} s on {timing['cores']} cores")
    print(f"-> {a.out}")


def add_command(bsub) -> None:
    p = bsub.add_parser("learn", help="new concepts learned from their pairs: the library against from scratch, "
                                      "and the questions asked back",
                        description="Build examples for the concepts of --programs (not among the 546), learn "
                                    "each from 10 and from 3 examples with the shipped library and from a uniform "
                                    "start, judge on 50 test pairs; then from 2 examples as vcc learn runs, count "
                                    "the ambiguous reports and whether one answered query settles them. "
                                    "Resumable: rerun the same command.")
    p.add_argument("--programs", default="benchmarks/learn/concepts.txt", help="`name: program` lines")
    p.add_argument("--dataset", help="their built examples (default: built under RUN/examples)")
    p.add_argument("--run", default="benchmarks/learn/run", type=runtime.out_folder,
                   help="run folder (results.jsonl, resumable)")
    p.add_argument("--budget", type=runtime.count(1, 10**10), default=500_000, help="programs per search (default 500000)")
    p.add_argument("--examples", default="10,3", type=runtime.counts(1, 10), help="examples per concept for the learning rows")
    p.add_argument("--ask-examples", type=runtime.count(1, 10), default=2, help="examples per concept for the asking rows")
    p.add_argument("--width", type=runtime.count(1, 4096), default=32, help="concepts searched in lockstep (default 32)")
    p.add_argument("--timing", action="store_true", help="also time vcc learn cold and warm (two processes)")
    p.add_argument("--quiet", action="store_true")
    p.add_argument("--out", default="benchmarks/results/learn.json", type=runtime.out_file(".json"), help="result JSON")
    p.set_defaults(fn=cmd_bench_learn)
