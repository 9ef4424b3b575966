"""`vcc learn` (a new concept from the user's example pairs) and `vcc library` (the
learned library: build it from a finished `vcc induce` run, or show the shipped one).

`vcc learn` reads and checks every pair before it searches, and writes its files only
once learning is over, each whole (a temporary file replaced): an interrupted or failed
run leaves the output folder as it was.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import tempfile
from pathlib import Path

from argpred.acted import FILTER_MODES
from vccjax import files as vfiles, runtime
from vccjax.errors import DataFileError, ProgramSyntaxError, VCCError, read_json
from vccjax.records import check_fields

QUERY_FILES = ("query.json", "query.png", "query_in.json")


def _settings(a: argparse.Namespace):
    from search.learn import LearnSettings

    fixate = None
    if a.fixate is not None:
        fixate = tuple(v.strip() for v in a.fixate.split(",") if v.strip())
        from vccjax.machine.instructions import FIXATE_TARGETS

        bad = [v for v in fixate if v not in FIXATE_TARGETS] or ([] if fixate else [a.fixate])
        if bad:
            raise VCCError(f"--fixate {a.fixate}: each value must be one of {', '.join(FIXATE_TARGETS)}")
    return LearnSettings(budget=a.budget, args=a.args, filters=a.filters, fixate=fixate, library=a.library,
                         rival_budget=a.rival_budget, fresh_scenes=a.fresh_scenes, seed=a.seed, parts=a.parts)


def _letter(k: int) -> str:
    return chr(ord("A") + k) if k < 26 else f"R{k}"


def concept_record(learned, examples: list[tuple[str, object, object]], files: list[str], settings) -> dict:
    """What `DIR/concept.json` holds: the program (subroutines expanded, runnable by
    `vcc run`), how it was found, the rivals, and the examples it was learned from."""
    r = learned.result
    rivals = [{"label": _letter(k + 1), "program": p.text(), "as_searched": text, "description_length": round(dl, 4),
               "differs_on_fresh_scenes": d, "runs_where_learned_fails": e}
              for k, (p, text, dl, d, e) in enumerate(learned.rivals())]
    return {
        "program": r.program.text(), "as_searched": r.text, "description_length": round(r.dl_nats, 4),
        "pairs_right": len(examples), "pairs": len(examples), "ambiguous": learned.ambiguous,
        "rivals": rivals, "fresh_scenes": learned.verdict.scenes if learned.verdict else 0,
        "learned_fails_on_fresh_scenes": learned.verdict.first_fails if learned.verdict else 0,
        "parts": [p.text() for p in learned.parts],
        "library": learned.library, "examples": files,
        "search": {"rank": r.rank, "programs_judged": r.programs, "seconds": round(r.seconds, 3),
                   "compile_seconds": round(r.compile_seconds, 3), "budget": r.budget},
        "settings": {"budget": settings.budget, "args": settings.args, "filters": settings.filters,
                     "fixate": settings.fixate,
                     "library": settings.library, "rival_budget": settings.rival_budget,
                     "rival_margin_nats": settings.rival_margin_nats, "seed": settings.seed,
                     "parts": settings.parts},
    }


def asked_before(out: Path, files: list[str]) -> list:
    """The programs the question in `out` was about (the program learned and its rivals),
    when the examples now hold every pair that question was learned from and more: the
    user answered it. A fresh search stops at the budget's cutoff, and the answer must
    not lose a rival the question was asked about (`search.learn.settle`)."""
    from vccjax.machine.program import parse

    path = out / "concept.json"
    if not path.is_file():
        return []
    old = read_json(path, DataFileError, "missing")
    try:
        check_fields(old, {"program": (str,), "rivals": (list,), "examples": (list,), "ambiguous": (bool,)}, str(path))
        if not all(isinstance(e, str) for e in old["examples"]):
            raise DataFileError(f"{path}: field 'examples' must list the pair files as strings")
        if not old["ambiguous"] or not set(old["examples"]) < set(files):
            return []
        return [parse(old["program"])] + [parse(check_fields(r, {"program": (str,)}, f"{path}: rival")["program"])
                                          for r in old["rivals"]]
    except ProgramSyntaxError as e:
        raise DataFileError(f"{path}: not a concept.json of vcc learn ({e})") from None


def _write_json(folder: Path, name: str, content) -> None:
    vfiles.write_json(folder / name, content)


def cmd_learn(a: argparse.Namespace) -> int:
    from search.learn import learn
    from vccjax.vision.examples_folder import pair_files, read_pairs
    from vccjax.world.user_concepts import check_name, save_concept

    settings = _settings(a)
    examples_dir, out_dir = Path(a.examples).resolve(), Path(a.out).resolve()
    if out_dir == examples_dir or examples_dir in out_dir.parents:
        raise VCCError(f"--out {a.out}: inside the examples folder {a.examples}, where its files would be read "
                       f"as pairs next time; write it elsewhere")
    if a.save and not a.name:
        raise VCCError("--save needs --name NAME (the name to run the concept by)")
    if a.name:
        check_name(a.name)
    if a.save:  # where it will be saved can be written: checked before the search, not after
        from vccjax.world.user_concepts import library_folder

        vfiles.check_writable(library_folder(), "concept library", folder=True)
    from argpred.features import MAX_OBJECTS

    # every pair read and checked before any search
    examples = read_pairs(a.examples, max_objects=None if settings.args == "uniform" else MAX_OBJECTS)
    files = [f"{p.name}:{hashlib.sha256(p.read_bytes()).hexdigest()[:16]}"
             for _, fin, fout in pair_files(a.examples) for p in (fin, fout)]
    pairs = [(i, o) for _, i, o in examples]
    runtime.prepare()
    from tqdm import tqdm

    print(f"{len(pairs)} pairs from {a.examples}; library: {settings.library}; arguments: {settings.args}"
          + (f"; fixate: {','.join(settings.fixate)}" if settings.fixate else ""))
    bar = tqdm(unit=" prefixes", unit_scale=True, disable=a.quiet, desc="searching")
    searcher = None
    if a.engine == "reference":
        from search.scalar import ScalarExplorer

        searcher = ScalarExplorer(width=1)
    asked = asked_before(Path(a.out), files)
    if asked:
        print(f"the pairs answer the question in {a.out}: its {len(asked)} programs are weighed too")
    learned = learn(pairs, settings, searcher, progress=lambda n: bar.update(n), asked=asked,
                    log=None if a.quiet else (lambda line: (bar.clear(), print(line))))
    bar.close()
    r = learned.result
    if not r.found:
        print(f"searched {r.programs:,} programs in {r.seconds:.1f} s")
        raise VCCError(f"no program under the budget ({settings.budget:,}) explains every pair; try a larger "
                       "--budget, more pairs, or --fixate to point out where to look")
    record = concept_record(learned, examples, files, settings)
    out = Path(a.out)
    vfiles.hold(out, "concept folder")  # one writer at a time
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=out, prefix=".learn-") as tmp:
        tmp = Path(tmp)
        written = _write_results(tmp, learned, record, pairs[0][0])
        old = ["concept.json", "trace.png", *QUERY_FILES, *(p.name for p in out.glob("query_out_*.json"))]
        for name in old:  # the old question goes with the old answer
            if name not in written and (out / name).exists():
                (out / name).unlink()
        for name in written:
            os.replace(tmp / name, out / name)
    _report(learned, record, out)
    if a.save:
        from vccjax.world.user_concepts import saved_concepts

        replaced = a.name in saved_concepts()
        path = save_concept(a.name, record)
        print(f"saved as {a.name!r} in {path.parent} (vcc run --concept {a.name})"
              + ("; it replaces the concept saved under that name before" if replaced else ""))
    return 0


def _write_results(folder: Path, learned, record: dict, first_input) -> list[str]:
    from vccjax.views.query import write_query
    from vccjax.views.trace import trace
    from vccjax.views.viewer import write_trace

    write_trace(trace(learned.program, first_input), folder / "trace.png")
    names = ["trace.png"]
    if learned.ambiguous:
        v, scene = learned.verdict, learned.query_scene
        cands = learned.candidates()
        answers = []  # one per distinct outcome on the query: the programs that give it
        for number, group in enumerate(v.answers, 1):
            labels = [_letter(k) for k in group]
            answers.append({"answer": number, "programs": {_letter(k): cands[v.programs[k]][0].text() for k in group},
                            "output": None if v.query_outputs[group[0]] is None
                            else v.query_outputs[group[0]].to_dict(), "labels": labels})
        _write_json(folder, "query.json", {
            "question": "which output do you mean for this input? Add the input and that output as one more pair "
                        "(copy query_in.json as <k>_in.json and the chosen query_out_<n>.json as <k>_out.json "
                        "into your examples folder, or draw the output you mean), then run vcc learn again",
            "input": scene.to_dict(), "answers": answers})
        _write_json(folder, "query_in.json", scene.to_dict())
        panels = [(f"{a['answer']}: " + ", ".join(a["labels"]), next(iter(a["programs"].values())),
                   v.query_outputs[group[0]]) for a, group in zip(answers, v.answers, strict=True)]
        write_query(folder / "query.png", scene, panels)
        names += list(QUERY_FILES)
        for a in answers:
            if a["output"] is not None:
                _write_json(folder, f"query_out_{a['answer']}.json", a["output"])
                names.append(f"query_out_{a['answer']}.json")
        record["query"] = {"files": names[1:], "answers": len(answers)}
    _write_json(folder, "concept.json", record)
    return ["concept.json", *names]


def _report(learned, record: dict, out: Path) -> None:
    r = learned.result
    print(f"learned ({len(r.program)} instructions, {r.dl_nats:.2f} nats, rank {r.rank:,}; "
          f"{r.programs:,} programs judged in {r.seconds:.1f} s, {r.compile_seconds:.1f} s of it compiling):")
    print(f"  {r.program.text()}")
    if r.text != r.program.text():
        print(f"  as searched: {r.text}")
    if learned.parts:
        others = ("its rivals are the other joins of parts that fit" if len(learned.candidates()) > 1
                  else "no other join of parts fits")
        print(f"learned in {len(learned.parts)} parts (nothing whole within the budget; {others}):")
        for k, part in enumerate(learned.parts, 1):
            print(f"  part {k}: {part.text()}")
    print(f"explains {record['pairs_right']} of {record['pairs']} pairs")
    n, fails = record["fresh_scenes"], record["learned_fails_on_fresh_scenes"]
    if fails:
        print(f"it fails on {fails} of {n} fresh scenes like the inputs (nothing is made there)")
    if learned.ambiguous:
        print(f"AMBIGUOUS: {len(record['rivals'])} other program(s) explain every pair but act otherwise on new scenes:")
        for rv in record["rivals"]:
            where = f"differs on {rv['differs_on_fresh_scenes']} of the {n - fails} fresh scenes where it runs"
            if fails:
                where += f"; runs on {rv['runs_where_learned_fails']} of the {fails} where it fails"
            print(f"  {rv['label']}: {rv['program']}  ({where})")
        print(f"question: {out / 'query.png'} (and query.json): add its input with the output you mean as a pair, "
              "and learn again")
    elif learned.parts and len(learned.candidates()) == 1:
        pass  # said above: no other join fits
    elif len(learned.candidates()) > 1:
        print(f"not ambiguous: the {len(learned.candidates()) - 1} other program(s) found that explain every pair "
              f"act alike on {n} fresh scenes")
    else:
        st = record["settings"]
        print(f"not ambiguous as far as searched: no other program that explains every pair was found "
              f"({st['rival_budget']:,} programs past the first fit, up to {st['rival_margin_nats']:g} nats "
              f"less probable)")
    print(f"wrote {out / 'concept.json'} and {out / 'trace.png'}")


def cmd_library_build(a: argparse.Namespace) -> int:
    from search.library import build, save

    content = build(a.source)
    sha = save(content, a.out)
    print(f"{len(content['card']['concepts'])} programs of {a.source}, {len(content['subroutines'])} subroutines "
          f"-> {a.out} (sha256 {sha[:12]}...)")
    return 0


def cmd_library_show(a: argparse.Namespace) -> int:
    from search.library import load, shipped_library

    lib = load(a.path)
    print(f"{a.path or shipped_library()}: sha256 {lib.sha256}")
    card = lib.card
    print(f"  from run {card['source_run']} ({card['settings'].get('args')} arguments, budget "
          f"{card['settings'].get('budget'):,}): {len(card['concepts'])} programs")
    print(f"  {len(lib.vocab.bodies)} subroutines, order {lib.model.order}, epsilon {lib.model.epsilon}")
    for name, sub in list(lib.vocab.subroutines().items())[: a.show]:
        print(f"  {name}: {'; '.join(sub.body)}")
    return 0


def add_commands(sub) -> None:
    p = sub.add_parser(
        "learn", help="learn a new concept from your own before/after pairs (JSON scenes or pictures)",
        description="Learn a program from EXAMPLES, a folder of pairs <k>_in.json/<k>_out.json (scenes) or "
                    "<k>_in.png/<k>_out.png (pictures), starting from the library learned on the 546 concepts. "
                    "Writes OUT/concept.json and OUT/trace.png; when the pairs leave the concept ambiguous, also "
                    "OUT/query.png and OUT/query.json, a new input to answer with one more pair.")
    p.add_argument("examples", metavar="EXAMPLES", help="folder of example pairs")
    p.add_argument("--out", required=True, type=runtime.out_folder,
                   help="folder for concept.json, trace.png and the query")
    p.add_argument("--budget", type=runtime.count(1, 10**10), default=500_000,
                   help="programs searched at most (default 500000)")
    p.add_argument("--library", default="shipped",
                   help="'shipped' (default: learned on the 546), 'uniform' (from scratch) or a library file; "
                        "what a library's search misses is searched from scratch over a tenth of the budget")
    p.add_argument("--args", choices=["predicted", "uniform"], default="predicted",
                   help="arguments: predicted by the CNN from the pairs (default) or uniform")
    p.add_argument("--filters", choices=FILTER_MODES, default="acted+raised",
                   help="with --args predicted: drop the filter values the objects acted on rule out (where one "
                        "pair changes three or more kinds of objects, only the values of an object left in place "
                        "stay) and raise those the pairs point in (the changed objects' kinds where at most two, "
                        "a landmark the moved objects end beside) (default); 'acted': drop only; 'network': the "
                        "network's filters alone, for a concept that acts on some objects through a filter and "
                        "on many kinds with none")
    p.add_argument("--fixate", help="the teacher's hint: where to look first (left, right, top, bottom, center; "
                                    "several comma-separated)")
    p.add_argument("--rival-budget", type=runtime.count(0, 10**10), default=2_000_000,
                   help="a second pass looks for rivals among the programs ranked up to this many past the first "
                        "fit (default 2000000; 0: none)")
    p.add_argument("--parts", type=runtime.count(1, 5), default=3,
                   help="when no program fits within the budget, learn one in up to this many parts, each bringing "
                        "the examples closer to their outputs, or continuing from where the first leaves the machine "
                        "(default 3; 1: never)")
    p.add_argument("--fresh-scenes", type=runtime.count(1, 10**5), default=100,
                   help="scenes the rivals are compared on (default 100)")
    p.add_argument("--seed", type=runtime.count(0), default=0, help="seed of the fresh scenes (default 0)")
    p.add_argument("--name", help="a name for the concept (with --save)")
    p.add_argument("--save", action="store_true",
                   help="add it to your concept library ($VCC_LIBRARY, default ~/.local/share/vccjax/concepts)")
    p.add_argument("--engine", choices=["jax", "reference"], default="jax",
                   help="search on the batched JAX emulator (default) or on the reference interpreter (no "
                        "compiling: quicker for small budgets)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(fn=cmd_learn)

    lib = sub.add_parser("library", help="the learned library: what explore-compress learned on the 546")
    lsub = lib.add_subparsers(dest="action", required=True)
    b = lsub.add_parser("build", help="rebuild it from a finished `vcc induce` run folder")
    b.add_argument("--from", dest="source", required=True, help="the run folder (run.json, results.jsonl)")
    b.add_argument("--out", required=True, type=runtime.out_file(".json"),
                   help="library file to write (the shipped one: search/data/library.json)")
    b.set_defaults(fn=cmd_library_build)
    s = lsub.add_parser("show", help="verify a library and summarise it")
    s.add_argument("path", nargs="?", help="library file (default: the shipped one)")
    s.add_argument("--show", type=runtime.count(0), default=10, help="subroutines to list (default 10)")
    s.set_defaults(fn=cmd_library_show)
