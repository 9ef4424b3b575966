"""`vcc induce`: explore-compress over concepts, resumable."""

from __future__ import annotations

import argparse
from pathlib import Path

from argpred.acted import FILTER_MODES
from vccjax import files, runtime
from vccjax.world.concepts import concept_list


def cmd_induce(a: argparse.Namespace) -> int:
    from search.induce import Settings, induce, needs_answer
    from search.run_summary import summary
    from vccjax.world.dataset import dataset_for

    runtime.on_cluster(a)
    settings = Settings(budget=a.budget, order=a.order, args=a.args, subroutines=a.subroutines == "on",
                        epsilon=a.epsilon, max_iterations=a.iterations, parts=a.parts,
                        arg_threshold=a.arg_threshold, fill=a.fill, filters=a.filters)
    if a.dataset:  # any built dataset: the concepts its manifest holds, their stored programs as answers
        from vccjax.world.dataset import Dataset

        ds = Dataset(a.dataset)
        names = concept_list(a.concepts, ds.concepts)
    else:
        names = concept_list(a.concepts)
    start = start_model(a.model, settings) if a.model else None
    if settings.args.startswith("predicted"):
        from argpred.predict import default_predictor

        default_predictor()  # a missing or corrupt weights file fails now, with its message
    if a.dataset and needs_answer(settings):
        for c in names:  # refuse now, not after an hour, a concept without a stored answer
            ds.program(c)
    runtime.prepare()
    if not a.dataset:
        ds = dataset_for(names, a.seed, a.dataset, progress=not a.quiet)
    for c in names:  # every concept's examples read and checked before the run folder is touched
        ds.arrays(c)
    if a.cluster == "ray":  # concepts in chunks of --width to Ray workers (search.cluster)
        from search.cluster import ClusterSearcher

        searcher = ClusterSearcher(workers=a.workers, width=a.width)
    else:
        from search.explore import Explorer

        searcher = Explorer(width=a.width)
    try:
        run = induce(names, ds.pairs, a.out, settings, explorer=searcher, progress=not a.quiet,
                     examples_sha256=ds.sha256, answers=ds.program, start=start)
    finally:
        if a.cluster == "ray":
            searcher.close()
    s = summary(run, names)
    files.write_json(Path(a.out) / "summary.json", s)
    print(f"{'concepts':<28}{s['concepts']}")
    print(f"{'induced':<28}{s['found']}")
    print(f"{'exact on all test pairs':<28}{s['exact_on_all_test_pairs']}")
    for it, k in s["per_iteration"].items():
        print(f"{'  new in iteration ' + str(it):<28}{k}")
    print(f"{'  without subroutines':<28}{s['found_without_subroutines']}")
    if s["found_in_last_pass"]:
        print(f"{'  new in the last pass':<28}{s['found_in_last_pass']} ({s['found_in_parts']} of them in parts)")
    print(f"{'wall time (s)':<28}{s['wall_seconds']:.1f} (all sessions of this run)")
    print(f"{'search time (s)':<28}{s['search_seconds']:.1f} (+{s['compile_seconds']:.1f} compiling)")
    print(f"{'programs searched':<28}{s['programs_covered']} ({s['programs_run']} run, rest pruned)")
    print(f"throughput: {s['programs_per_second']} programs/s searched, "
          f"{s['programs_run_per_second']} programs/s run on all examples")
    return 0


def start_model(spec: str, settings):
    """The model `--model` names: 'library' (the shipped one), a library file, or a
    `model-K.json` a `vcc induce` run wrote; checked against the run's order."""
    import numpy as np

    from search.library import load
    from search.model import MarkovModel, Vocabulary
    from vccjax.errors import DataFileError, read_json

    if spec == "library":
        lib = load()
        vocab, model = lib.vocab, lib.model
    else:
        content = read_json(spec, DataFileError, "no such model file")
        if isinstance(content, dict) and content.get("format") == "vccjax-library":
            lib = load(spec)
            vocab, model = lib.vocab, lib.model
        else:
            try:
                vocab = Vocabulary.from_json(content["subroutines"])
                logp = np.array(content["logp"], float)
                order = int(content["order"])
            except (KeyError, TypeError, ValueError) as e:
                raise DataFileError(f"{spec}: not a library or a model-K.json of vcc induce ({e})") from None
            if logp.shape != (vocab.size + 1, vocab.size + 1) or not np.all(np.isfinite(logp)):
                raise DataFileError(f"{spec}: transition table of shape {logp.shape}, expected "
                                    f"{(vocab.size + 1, vocab.size + 1)} finite values")
            model = MarkovModel(logp, order, settings.epsilon)
    if model.order != settings.order:
        raise DataFileError(f"{spec}: a model of order {model.order}, this run has --order {settings.order}")
    return vocab, model


def add_commands(sub) -> None:
    p = sub.add_parser(
        "induce", help="induce programs for concepts from their examples (explore-compress)",
        description="Explore-compress: search each concept's programs in order of description length "
                    "under the current model, then refit the model (and subroutines) on what was found, "
                    "and repeat. Results go to OUT/results.jsonl after every concept; rerunning the same "
                    "command resumes.",
    )
    p.add_argument("--concepts", type=runtime.name_list, default="all",
                   help="'all' (default: the 546, or every concept of --dataset), 'demo' (a dozen short ones) "
                        "or a comma-separated list")
    p.add_argument("--out", required=True, type=runtime.out_folder,
                   help="run folder (created; an existing one is resumed)")
    p.add_argument("--budget", type=runtime.count(1, 10**10), default=500_000,
                   help="programs per concept (default 500000)")
    p.add_argument("--order", type=int, choices=[0, 1], default=1, help="Markov order (default 1)")
    p.add_argument("--args", default="predicted",
                   choices=["uniform", "uniform+fixation", "oracle", "predicted", "predicted+fixation"],
                   help="argument model (default predicted: the CNN on the training pairs; oracle and "
                        "+fixation read the program stored with each concept's examples, research settings)")
    p.add_argument("--model", help="start from a learned model: 'library' (the shipped one), a library file, "
                                   "or a run's model-K.json; then one pass over the concepts")
    p.add_argument("--subroutines", choices=["on", "off"], default="on")
    p.add_argument("--epsilon", type=runtime.number(0, 1), default=0.1, help="pseudocount (default 0.1)")
    p.add_argument("--iterations", type=runtime.count(1, 100), default=8, help="explore-compress iterations at most")
    p.add_argument("--arg-threshold", type=runtime.number(0, 1, above=True), default=0.55,
                   help="with --args predicted: an argument passes at this predicted probability (default 0.55, "
                        "the paper's); a function none of whose arguments pass is left out")
    p.add_argument("--fill", choices=["gained", "predicted"], default="gained",
                   help="with --args predicted: fill_color's arguments are the colours some object gains in the "
                        "pairs (default; exact: only fill_color changes a colour), or 'predicted' by the network "
                        "as the filters (the paper's)")
    p.add_argument("--filters", choices=FILTER_MODES, default="acted+raised",
                   help="with --args predicted: drop the shape and colour filter values the objects acted on rule "
                        "out (where one pair changes three or more kinds of objects, only values of an object left "
                        "in place stay) and raise to the threshold those the pairs point in (the kinds of the "
                        "changed objects where they are at most two, a landmark the moved objects end beside) "
                        "(default); 'acted': drop only; 'network': the network's filters alone (the paper's)")
    p.add_argument("--parts", type=runtime.count(1, 3), default=1,
                   help="2 or 3: after the iterations, a last pass over the concepts still missed, each "
                        "searched whole with the model of everything found and, where that fails, in up to "
                        "this many parts (each part a tenth of the budget, all at most 1.3 budgets; "
                        "docs/search.md); 1 (default): no such pass. A finished run resumed with --parts 2 "
                        "or 3 adds it")
    p.add_argument("--dataset", help="a built dataset folder (default: the one shipped with vccjax, seed 0)")
    p.add_argument("--seed", type=runtime.count(0), default=0,
                   help="examples' seed without --dataset: 0 (default) is the shipped dataset; another "
                        "builds these concepts' examples under ~/.cache/vccjax")
    p.add_argument("--width", type=runtime.count(1, 4096), default=32,
                   help="concepts searched in lockstep, their programs stepped in shared batches (default 32)")
    runtime.cluster_flags(p, "search each iteration's concepts on Ray workers, --width concepts a chunk")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(fn=cmd_induce)
