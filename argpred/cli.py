"""`vcc argpred data|train|eval`: the argument predictor's data, training and recall."""

from __future__ import annotations

import argparse
import datetime
import shlex
import subprocess
from pathlib import Path

from argpred.acted import FILTER_MODES
from vccjax import runtime

DEFAULT_DATA = Path.home() / ".cache" / "vccjax" / "argpred-data"


def _write_json(path: Path, data: dict) -> None:
    """`path`, replaced whole: a failed write leaves no cut file."""
    from vccjax import files

    files.write_json(path, data)


def _now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def _commit() -> str | None:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              cwd=Path(__file__).parent, timeout=10).stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        return None


def _eval_command(weights: str | None = None, concepts: str = "all", dataset: str | None = None,
                  out: str | None = None, record: bool = False, threshold: float = 0.55,
                  fill: str = "predicted", filters: str = "network") -> str:
    """The `vcc argpred eval` command line that measures this (options left at their
    defaults are left out)."""
    parts = ["vcc", "argpred", "eval"]
    for flag, value, default in (("--weights", weights, None), ("--concepts", concepts, "all"),
                                 ("--dataset", dataset, None), ("--threshold", threshold, 0.55),
                                 ("--fill", fill, "predicted"), ("--filters", filters, "network"),
                                 ("--out", out, None)):
        if value != default:
            parts += [flag, str(value)]
    return shlex.join(parts + (["--record"] if record else []))


def cmd_data(a: argparse.Namespace) -> int:
    import os

    from argpred.data import build, built

    joined = 0.0 if a.kind != "drawn" else a.joined
    m = build(a.out, a.programs, seed=a.seed, workers=a.workers or os.cpu_count() or 1, progress=not a.quiet,
              joined=joined, kind=a.kind)
    print(f"{len(m['shards'])} shards ({built(a.out)['programs']} {a.kind} programs) in {a.out}")
    return 0


def cmd_train(a: argparse.Namespace) -> int:
    import os
    import time

    import numpy as np

    from argpred import data as argdata
    from argpred.recall import card_record, measure
    from argpred.train import TrainSettings, train_members
    from argpred.weights import record, save

    out = Path(a.out)
    if a.pool == "hidden" and not a.hidden:
        raise ValueError("--pool hidden pools the hidden channels: give --hidden above 0")
    if out.is_dir():
        raise ValueError(f"--out {out}: a folder; give the weights file to write")
    start = time.time()
    folders = [f for f in (a.data or "").split(",") if f]
    if len(folders) > 1:  # several built folders, trained on together (each verified, none redrawn)
        missing = [f for f in folders if argdata.built(f) is None]
        if missing:
            raise ValueError(f"not a built data folder: {', '.join(missing)} (build with `vcc argpred data`)")
        parts = [argdata.load(f) for f in folders]
        data = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    else:
        have = argdata.built(folders[0]) if folders else None  # an existing folder keeps its count and draw
        programs = a.programs or (have or {}).get("programs", 1000)
        joined = a.joined if a.joined is not None else (have or {}).get("joined", 0.3)
        tag = f"-joined{joined:g}" if joined else ""
        folder = Path(folders[0]) if folders else DEFAULT_DATA / f"seed{a.seed}-{programs}{tag}"
        argdata.build(folder, programs, seed=have["seed"] if have else a.seed,
                      workers=a.workers or os.cpu_count() or 1, progress=not a.quiet, joined=joined)
        data = argdata.load(folder)
    for kind, n in (("carry", a.carry), ("loop", a.loops)):  # argpred.data.carry_program, loop_program
        if n and not any((argdata.built(f) or {}).get("kind") == kind for f in folders):
            extra = DEFAULT_DATA / f"seed{a.seed}-{kind}{n}"
            argdata.build(extra, n, seed=a.seed, progress=not a.quiet, kind=kind)
            more = argdata.load(extra)
            data = {k: np.concatenate([data[k], more[k]]) for k in data}
    settings = TrainSettings(hidden=a.hidden, kernel=a.kernel, depth=a.depth, evidence=a.evidence,
                             bias_start=a.bias_start, pool=a.pool, epochs=a.epochs, batch=a.batch, learning_rate=a.lr, l1=a.l1,
                             positive_weight=a.positive_weight, seed=a.seed)
    model, params, histories = train_members(data, settings, a.members, checkpoint=out.with_suffix(".ckpt"),
                                             workers=a.workers or os.cpu_count() or 1, progress=not a.quiet)
    sha = save(out, model, params, {"settings": {k: getattr(settings, k) for k in settings.__dataclass_fields__},
                                    "programs": int(len(data["labels"])),
                                    "history": histories[0] if a.members == 1 else histories})
    for k, history in enumerate(histories):
        last = history[-1]
        who = f"member {k} (seed {a.seed + k}) " if a.members > 1 else ""
        print(f"{who}trained on {len(data['labels'])} programs: "
              f"train bce {last['train_bce']:.4f}, held-out bce {last.get('val_bce', float('nan')):.4f}, "
              f"held-out programs with every label right {last.get('val_all_labels_right', float('nan')):.3f}")
    print(f"{a.members} member(s) in {time.time() - start:.0f}s")
    r, _ = measure(out)  # the card keeps the recall these weights were made with
    record(out, recall=card_record(r, _now(), _eval_command(weights=str(out))))
    print(f"concepts recalled: {r['recalled']} of {r['concepts']} (recall {r['recall']:.4f}; in the card)")
    print(f"weights: {out} (sha256 {sha})")
    return 0


def cmd_recall(a: argparse.Namespace) -> int:
    import time

    from argpred.recall import card_record, measure
    from argpred.weights import record
    from vccjax.world.concepts import concept_list

    names = concept_list(a.concepts)
    if a.record and (a.concepts != "all" or a.dataset or a.threshold != 0.55 or a.fill != "predicted"
                     or a.filters != "network"):
        raise ValueError("--record keeps the weights' own recall on all the concepts' shipped examples at 0.55 in "
                         "the weights card: leave out --concepts, --dataset, --threshold, --fill and --filters")
    start = time.time()
    r, card = measure(a.weights, names, a.dataset, a.threshold, a.fill, a.filters)
    seconds = time.time() - start
    date = _now()
    if a.out:
        _write_json(Path(a.out), {
            "benchmark": "argpred-recall", "date": date, "commit": _commit(),
            "command": _eval_command(a.weights, a.concepts, a.dataset, a.out, a.record, a.threshold, a.fill,
                                     a.filters),
            "weights": a.weights or "shipped", "weights_sha256": card["sha256"],
            "members": card["model"].get("members", 1), "dataset": a.dataset or "shipped", "split": "train",
            "seconds": round(seconds, 2), **r})
    if a.record:
        record(a.weights, recall=card_record(r, date, _eval_command(a.weights)))
    for c, miss in list(r["missed"].items())[: a.show]:
        print(f"missed  {c}: " + "; ".join(f"{f}({', '.join(v)})" for f, v in miss.items()))
    print(f"mean extra arguments per function at threshold {a.threshold:g}: "
          + ", ".join(f"{f} {v:.2f}" for f, v in r["mean_extra_arguments"].items()))
    print(f"weights sha256 {card['sha256']}; {r['concepts']} concepts in {seconds:.1f} s"
          + (f"; result: {a.out}" if a.out else "") + ("; recorded in the weights card" if a.record else ""))
    print(f"concepts recalled: {r['recalled']} of {r['concepts']}")
    print(f"recall: {r['recall']:.4f}")
    return 0


def add_commands(sub) -> None:
    p = sub.add_parser("argpred", help="argument prediction: training data, training, recall on the concepts")
    s = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    d = s.add_parser("data", help="draw training programs and their examples (resumable, seeded)")
    d.add_argument("--out", required=True, type=runtime.out_folder, help="data folder (an existing one is resumed)")
    d.add_argument("--programs", type=runtime.count(1, 10**7), default=1000, help="programs to draw (default 1000)")
    d.add_argument("--seed", type=runtime.count(0), default=0)
    d.add_argument("--joined", type=runtime.number(0, 1), default=0.3,
                   help="share of programs drawn as two parts joined by reset_attn (default 0.3, as the "
                        "shipped weights)")
    d.add_argument("--kind", choices=("drawn", "carry", "loop"), default="drawn",
                   help="drawn (default): programs of 3 to 6 instructions; carry: an object carried onto "
                        "another one (what `train --carry` adds); loop: one change done to every attended object "
                        "(what `train --loops` adds)")
    d.add_argument("--workers", type=runtime.count(0, 256), default=0, help="processes (default: one per core)")
    d.add_argument("--quiet", action="store_true")
    d.set_defaults(fn=cmd_data)

    t = s.add_parser("train", help="train the CNN (data built or resumed first); checkpoints every epoch",
                     description="Build (or reuse) the training programs, train the argument CNN with "
                                 "optax, and write the weights (msgpack + JSON card with its sha256). "
                                 "An interrupted run resumes from OUT.ckpt. The defaults reproduce the "
                                 "shipped weights.")
    t.add_argument("--out", default="argpred-weights.msgpack", type=runtime.out_file(".msgpack"),
                   help="weights file (default argpred-weights.msgpack)")
    t.add_argument("--data", help=f"data folder (default {DEFAULT_DATA}/seedS-N; built there, or its build "
                                  "resumed, when it is not complete), or several built ones, comma-separated, "
                                  "to train on together")
    t.add_argument("--programs", type=runtime.count(1, 10**7), default=None,
                   help="training programs (default: all of an existing --data folder, else 1000)")
    t.add_argument("--epochs", type=runtime.count(1, 10**5), default=30)
    t.add_argument("--batch", type=runtime.count(1, 2**16), default=64)
    t.add_argument("--lr", type=runtime.number(0, 10, above=True), default=3e-3, help="Adam learning rate")
    t.add_argument("--l1", type=runtime.number(0, 10), default=1e-4, help="L1 weight on the kernels")
    t.add_argument("--positive-weight", type=runtime.number(0, 10**4, above=True), default=16.0,
                   help="loss weight of a used argument (>1 favours recall over extra arguments)")
    t.add_argument("--hidden", type=runtime.count(0, 4096), default=32,
                   help="hidden channels (0: the paper's single convolution)")
    t.add_argument("--joined", type=runtime.number(0, 1), default=None,
                   help="share of two-part programs in newly drawn data (default: the folder's, else 0.3)")
    t.add_argument("--kernel", type=runtime.count(1, 15), default=3)
    t.add_argument("--depth", type=runtime.count(1, 8), default=1, help="hidden convolutions (with --hidden > 0)")
    t.add_argument("--evidence", choices=("signed", "relu", "shown"), default="relu",
                   help="relu (default): an example adds evidence for an argument or nothing; signed: the "
                        "paper's plain sum, where examples that do not show an argument count against it; "
                        "shown: an example speaks, for or against, only of a value its objects show")
    t.add_argument("--bias-start", type=runtime.number(-100, 100), default=-4.0,
                   help="first bias of every label under --evidence relu")
    t.add_argument("--carry", type=runtime.count(0, 10**6), default=30,
                   help="carry programs (an object carried onto another one: 10 instructions, beyond the drawn "
                        "six) added to the data, drawn into DEFAULT/seedS-carryN (default 30; 0: none)")
    t.add_argument("--pool", choices=("labels", "hidden"), default="labels",
                   help="labels (default): each label's map max-pooled over the grid; hidden: the hidden channels "
                        "pooled, then a dense layer (a label can weigh the whole grid)")
    t.add_argument("--loops", type=runtime.count(0, 10**6), default=0,
                   help="loop programs (one change done to every attended object, after an optional filter) "
                        "added to the data, drawn into DEFAULT/seedS-loopN (default 0: none)")
    t.add_argument("--members", type=runtime.count(1, 64), default=3,
                   help="networks trained from seeds S, S+1, ... whose probabilities are averaged (default 3)")
    t.add_argument("--seed", type=runtime.count(0), default=0)
    t.add_argument("--workers", type=runtime.count(0, 256), default=0,
                   help="processes for the data (default: one per core)")
    t.add_argument("--quiet", action="store_true")
    t.set_defaults(fn=cmd_train)

    e = s.add_parser("eval", help="recall on the 546 concepts' training pairs; prints `recall: X` last")
    e.add_argument("--weights", help="weights file (default: the shipped weights)")
    e.add_argument("--concepts", type=runtime.name_list, default="all",
                   help="'all' (default), 'demo' or a comma-separated list")
    e.add_argument("--dataset", help="dataset folder (default: the shipped one)")
    e.add_argument("--threshold", type=runtime.number(0, 1, above=True), default=0.55,
                   help="an argument passes at this probability (default 0.55, the paper's; what `vcc induce "
                        "--arg-threshold` searches with)")
    e.add_argument("--fill", choices=["predicted", "gained"], default="predicted",
                   help="fill_color's arguments: 'predicted' by the network (default: the weights' own figures) "
                        "or 'gained', the colours some object gains in the pairs (what `vcc induce` searches "
                        "with by default; argpred.gained)")
    e.add_argument("--filters", choices=FILTER_MODES, default="network",
                   help="the filters' arguments: the network's alone (default: the weights' own figures) or "
                        "'acted', less the values the objects acted on rule out, or 'acted+raised', also with "
                        "the values the pairs point in raised (what `vcc induce` searches with by default; "
                        "argpred.acted)")
    e.add_argument("--out", "--json", dest="out", type=runtime.out_file(".json"),
                   help="write the result JSON here: recall, concepts recalled, misses, mean extra arguments "
                        "per function, the weights' sha256, date, commit and command")
    e.add_argument("--record", action="store_true",
                   help="also keep the recall (all concepts, shipped examples) in the weights card; the "
                        "weights file itself is not rewritten")
    e.add_argument("--show", type=runtime.count(0), default=10, help="missed concepts to list (default 10)")
    e.set_defaults(fn=cmd_recall)
