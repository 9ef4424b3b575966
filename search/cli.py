"""`vcc induce`: explore-compress over concepts, resumable."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path


def enable_compile_cache() -> None:
    """Keep compiled emulator steps across runs (XLA's persistent cache); VCCJAX_CACHE=off
    turns it off, another value moves it."""
    where = os.environ.get("VCCJAX_CACHE", str(Path.home() / ".cache" / "vccjax" / "jax"))
    if where.lower() == "off":
        return
    import jax

    jax.config.update("jax_compilation_cache_dir", where)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.5)


DEMO: tuple[str, ...] = (  # a dozen short concepts: `--concepts demo` (all found in under a minute on 2 cores)
    "change_target_obj_to_given_color", "change_target_position_to_given_color", "remove_bottom_obj",
    "remove_given_target_color_objs", "remove_given_target_shape_objs", "remove_left_most_obj",
    "remove_right_most_obj", "remove_top_obj", "remove_given_target_shape_and_color_combo_objs",
    "move_to_bottom_edge", "move_to_right_edge", "move_to_top_edge")


def concept_list(spec: str) -> list[str]:
    from vccjax.concepts import concept_names

    names = concept_names()
    if spec == "all":
        return names
    if spec == "demo":
        return list(DEMO)
    chosen = [c.strip() for c in spec.split(",") if c.strip()]
    unknown = [c for c in chosen if c not in names]
    if unknown:
        raise ValueError(f"unknown concept(s): {', '.join(unknown)} (see `vcc concepts`)")
    return chosen


def cmd_induce(a: argparse.Namespace) -> int:
    from search.induce import Settings, induce, summary
    from vccjax.dataset import dataset_for

    settings = Settings(budget=a.budget, order=a.order, args=a.args, subroutines=a.subroutines == "on",
                        epsilon=a.epsilon, max_iterations=a.iterations)
    names = concept_list(a.concepts)
    if settings.args.startswith("predicted"):
        from argpred.predict import default_predictor

        default_predictor()  # a missing or corrupt weights file fails now, with its message
    enable_compile_cache()
    ds = dataset_for(names, a.seed, a.dataset, progress=not a.quiet)
    from search.explore import Explorer

    run = induce(names, ds.pairs, a.out, settings, explorer=Explorer(width=a.width), progress=not a.quiet,
                 examples_sha256=ds.sha256)
    s = summary(run, names)
    (Path(a.out) / "summary.json").write_text(json.dumps(s, indent=1))
    print(f"{'concepts':<28}{s['concepts']}")
    print(f"{'induced':<28}{s['found']}")
    print(f"{'exact on all test pairs':<28}{s['exact_on_all_test_pairs']}")
    for it, k in s["per_iteration"].items():
        print(f"{'  new in iteration ' + str(it):<28}{k}")
    print(f"{'  without subroutines':<28}{s['found_without_subroutines']}")
    print(f"{'wall time (s)':<28}{s['wall_seconds']:.1f} (all sessions of this run)")
    print(f"{'search time (s)':<28}{s['search_seconds']:.1f} (+{s['compile_seconds']:.1f} compiling)")
    print(f"{'programs searched':<28}{s['programs_covered']} ({s['programs_run']} run, rest pruned)")
    print(f"throughput: {s['programs_per_second']} programs/s searched, "
          f"{s['programs_run_per_second']} programs/s run on all examples")
    return 0


def add_commands(sub) -> None:
    p = sub.add_parser(
        "induce", help="induce programs for concepts from their examples (explore-compress)",
        description="Explore-compress: search each concept's programs in order of description length "
                    "under the current model, then refit the model (and subroutines) on what was found, "
                    "and repeat. Results go to OUT/results.jsonl after every concept; rerunning the same "
                    "command resumes.",
    )
    p.add_argument("--concepts", default="all",
                   help="'all' (default), 'demo' (a dozen short ones) or a comma-separated list")
    p.add_argument("--out", required=True, help="run folder (created; an existing one is resumed)")
    p.add_argument("--budget", type=int, default=500_000, help="programs per concept (default 500000)")
    p.add_argument("--order", type=int, choices=[0, 1], default=1, help="Markov order (default 1)")
    p.add_argument("--args", default="oracle",
                   choices=["uniform", "uniform+fixation", "oracle", "predicted", "predicted+fixation"],
                   help="argument model (default oracle: the values the reference program uses)")
    p.add_argument("--subroutines", choices=["on", "off"], default="on")
    p.add_argument("--epsilon", type=float, default=0.1, help="pseudocount (default 0.1)")
    p.add_argument("--iterations", type=int, default=8, help="explore-compress iterations at most")
    p.add_argument("--dataset", help="a built dataset folder (default: the one shipped with vccjax, seed 0)")
    p.add_argument("--seed", type=int, default=0,
                   help="examples' seed without --dataset: 0 (default) is the shipped dataset; another "
                        "builds these concepts' examples under ~/.cache/vccjax")
    p.add_argument("--width", type=int, default=32,
                   help="concepts searched in lockstep, their programs stepped in shared batches (default 32)")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(fn=cmd_induce)
