"""`vcc bench misses`: why each concept an induction run missed was missed.

For every concept the run did not find, its best known program (the reference program, or
one another committed run found) is spelt as cheaply as the run's last model allows (its subroutines and order-1 transitions, the concept's argument
beliefs under the run's `--args`): either some argument the program needs has no
probability (an argument the predictor did not predict, or fixation guidance left out),
or the program has a rank under that model, which lies past the run's budget (the search
covers the budget's most probable programs). docs/search.md lists the result.

`--model K` ranks under the run's model-K.json instead (model-0: the uniform start), and
`--concepts` names the concepts to rank, found or not: where a concept stood at an
earlier iteration, for instance the first loop concept under the uniform start.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from vccjax import files, runtime

RANK_CAP = 2**62  # ranks past this are reported as None ("past 4.6e18")


def _found_elsewhere(folders: list[Path], concepts: set[str]) -> dict[str, list]:
    """Programs other runs (results.jsonl under `folders`) found for `concepts`."""
    from vccjax.machine.program import parse

    out: dict[str, list] = {}
    for folder in folders:
        for path in sorted(folder.rglob("results.jsonl")) if folder.exists() else []:
            for line in path.read_text().splitlines():
                r = json.loads(line) if line.strip() else {}
                if r.get("found") and r.get("concept") in concepts and r.get("program"):
                    p = parse(r["program"])
                    if p not in out.setdefault(r["concept"], []):
                        out[r["concept"]].append(p)
    return out


def why_missed(folder: Path, others: list[Path] = (), model_index: int | None = None,
               concepts: list[str] | None = None) -> dict:
    """Each missed concept's (or each of `concepts`') cheapest known program and its rank
    under the run's last model (or model-`model_index`.json)."""
    from search.arguments import argument_logp
    from search.chain import Chain
    from search.model import MarkovModel, Vocabulary
    from search.parts import fits
    from vccjax.errors import DataFileError, read_json
    from vccjax.machine.instructions import NAMES, arg_domain
    from vccjax.world.concepts import reference_program
    from vccjax.world.dataset import dataset_for

    meta = read_json(folder / "run.json", DataFileError, "missing (not an induction run folder)")
    settings = meta["settings"]
    records = [json.loads(line) for line in (folder / "results.jsonl").read_text().splitlines() if line.strip()]
    found = {r["concept"] for r in records if r["found"]}
    missed = sorted({r["concept"] for r in records} - found)
    if concepts is not None:
        unknown = sorted(set(concepts) - {r["concept"] for r in records})
        if unknown:
            raise DataFileError(f"{folder}: the run searched no concept {', '.join(unknown[:3])}")
        missed = list(concepts)
    models = sorted(folder.glob("model-*.json"), key=lambda p: int(p.stem.split("-")[1]))
    if not models:
        raise DataFileError(f"{folder}: no model-K.json (not a vcc induce run folder)")
    if model_index is not None:
        models = [m for m in models if m.stem == f"model-{model_index}"]
        if not models:
            raise DataFileError(f"{folder}: no model-{model_index}.json")
    content = read_json(models[-1], DataFileError, "missing")
    vocab = Vocabulary.from_json(content["subroutines"])
    model = MarkovModel(np.array(content["logp"], float), int(content["order"]), float(settings["epsilon"]))
    ds = dataset_for(missed, 0, None, progress=False)
    rows = []
    known = _found_elsewhere(others, set(missed))
    for c in missed:
        answer = reference_program(c)
        logp = argument_logp(settings["args"], ds.pairs(c, "train"), answer,
                             threshold=settings.get("arg_threshold", 0.55), fill=settings.get("fill", "predicted"),
                             filters=settings.get("filters", "network"))
        chain = Chain(vocab, model, logp, float(settings.get("delta", 0.01)))
        row = {"concept": c, "instructions": len(answer.ops)}

        def unpredicted(p) -> list[str]:
            return sorted({f"{NAMES[o]}({arg_domain(NAMES[o])[a]})" for o, a in zip(p.ops, p.args)
                           if arg_domain(NAMES[o]) and not np.isfinite(logp[o][a])})

        best = None  # (nats, portions, program): the cheapest spelling of a known program
        pairs = ds.pairs(c, "train")
        # another run's program counts only where it fits this run's examples (it may come
        # from fewer or other examples)
        for p in [answer, *(k for k in known.get(c, []) if fits(k, pairs))]:
            spelt = None if unpredicted(p) else chain.cheapest(p.ops, p.args)
            if spelt is not None and (best is None or spelt[0] < best[0]):
                best = (spelt[0], spelt[1], p)
        if best is None:
            row |= {"why": "argument not predicted", "unpredicted": unpredicted(answer)}
        else:
            spelt, program = best[:2], best[2]
            row["program"] = "reference" if program == answer else program.text()
            bins = chain.program_bins(spelt[1])
            counts = chain.count_table(budget=RANK_CAP, max_bins=bins)  # stops once RANK_CAP programs are cheaper
            rank = int(counts[bins - 1]) + 1 if 0 < bins <= len(counts) else (1 if bins == 0 else None)
            row |= {"why": "past the budget" if rank is None or rank > settings["budget"] else "within the budget",
                    "rank": rank, "nats": round(float(spelt[0]), 2)}
        rows.append(row)
    from argpred.weights import load as load_weights

    return {"run": str(folder), "settings": settings, "model": models[-1].name,
            "concepts": len({r["concept"] for r in records}),
            "found": len(found), "predictor_sha256": load_weights()[2]["sha256"],
            "run_predictor_sha256": meta.get("predictor_sha256"), "misses": rows}


def cmd_bench_misses(a: argparse.Namespace) -> int:
    from vcc.bench import stamp

    runtime.prepare()
    others = [Path(x) for x in a.known.split(",") if x.strip()]
    concepts = [c for c in a.concepts.split(",") if c] if a.concepts else None
    report = {**stamp(a, "misses"), "benchmark": "misses",
              **why_missed(Path(a.run), others, model_index=a.model, concepts=concepts)}
    files.write_json(a.out, report)
    for r in report["misses"]:
        why = (", ".join(r["unpredicted"]) + " not predicted" if r["why"] == "argument not predicted"
               else f"rank {r['rank']:,}" if r["rank"] is not None else "rank past 4.6e18")
        why += "" if r["why"] == "argument not predicted" else f" ({r['nats']} nats) under {report['model']}"
        print(f"{r['concept']} ({r['instructions']} instructions): {why}")
    what = "ranked" if concepts is not None else "missed"
    print(f"{len(report['misses'])} {what} of {report['concepts']}   -> {a.out}")
    if report["run_predictor_sha256"] not in (None, report["predictor_sha256"]):
        print("(the run was made with other argument-predictor weights than these: predicted arguments may differ)")
    return 0


def add_command(bsub) -> None:
    m = bsub.add_parser("misses", help="why each concept an induction run missed was missed",
                        description="For each concept a run folder did not find: the argument its reference "
                                    "program needs that the run's argument beliefs rule out, or the program's "
                                    "rank under the run's last model (against the budget).")
    m.add_argument("--run", required=True, help="a vcc induce run folder (run.json, results.jsonl, model-K.json)")
    m.add_argument("--known", default="benchmarks/induction,benchmarks/reproduce",
                   help="folders whose runs' found programs count as known programs too (comma-separated; '' none)")
    m.add_argument("--model", type=runtime.count(0), default=None,
                   help="rank under the run's model-K.json (default: its last; 0: the uniform start)")
    m.add_argument("--concepts", type=runtime.name_list, default=None,
                   help="concepts to rank, found or not (comma-separated; default: the ones the run missed)")
    m.add_argument("--out", default="benchmarks/results/misses.json", type=runtime.out_file(".json"),
                   help="result JSON")
    m.set_defaults(fn=cmd_bench_misses)
