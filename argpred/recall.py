"""How well the predictor serves the search on the 546 concepts (their training pairs
only; no concept is used in training): a concept is recalled when every argument its
reference program gives a predicted function passes 0.55 (the search then can find
it); extra arguments are those that pass though the reference does not use them
(each one widens the search)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from argpred.acted import with_filters
from argpred.data import PREDICTED
from argpred.gained import with_fill
from argpred.predict import THRESHOLD, Predictor, passing
from vccjax.world.concepts import reference_program
from vccjax.machine.instructions import NAMES, arg_domain
from vccjax.machine.scene import Scene


def used_arguments(concept: str) -> dict[str, set[str]]:
    p = reference_program(concept)
    used: dict[str, set[str]] = {f: set() for f in PREDICTED}
    for o, a in zip(p.ops, p.args):
        if NAMES[o] in PREDICTED:
            used[NAMES[o]].add(arg_domain(NAMES[o])[a])
    return used


def recall(predictor: Predictor, concepts: Sequence[str],
           pairs: Callable[[str], list[tuple[Scene, Scene]]], threshold: float = THRESHOLD,
           fill: str = "predicted", filters: str = "network") -> dict:
    """Recall and extra arguments; `fill` 'gained' takes fill_color's from the pairs
    (`argpred.gained`), `filters` 'acted' drops the filter values the objects acted on rule
    out, 'acted+raised' also raises those the pairs point in (`argpred.acted`), as the
    search does by default."""
    missed: dict[str, dict[str, list[str]]] = {}
    extra = {f: [] for f in PREDICTED}
    extras: dict[str, dict[str, list[str]]] = {}  # per concept, the arguments passed that it never uses
    unused, kept = dict.fromkeys(PREDICTED, 0), dict.fromkeys(PREDICTED, 0)
    for c in concepts:
        ok = passing(with_filters(with_fill(predictor.for_pairs(pairs(c)), pairs(c), fill), pairs(c), filters,
                                  threshold=threshold), threshold)
        used = used_arguments(c)
        miss = {f: sorted(used[f] - set(ok[f])) for f in PREDICTED if used[f] - set(ok[f])}
        if miss:
            missed[c] = miss
        for f in PREDICTED:
            more = sorted(set(ok[f]) - used[f])
            extra[f].append(len(more))
            if more:
                extras.setdefault(c, {})[f] = more
            if not used[f]:  # a function the concept never uses stays in its search if any argument passes
                unused[f] += 1
                kept[f] += bool(ok[f])
    return {
        "concepts": len(concepts), "threshold": threshold, "fill": fill, "filters": filters,
        "recalled": len(concepts) - len(missed),
        "recall": (len(concepts) - len(missed)) / len(concepts),
        "mean_extra_arguments": {f: float(np.mean(v)) for f, v in extra.items()},
        "unused_function_kept": {f: {"kept": kept[f], "of_concepts_not_using_it": unused[f]} for f in PREDICTED},
        "missed": missed, "extra_arguments": extras,
    }


def measure(weights=None, concepts: Sequence[str] | None = None, dataset=None,
            threshold: float = THRESHOLD, fill: str = "predicted", filters: str = "network") -> tuple[dict, dict]:
    """(`recall` of the weights at `weights` (default: the shipped ones) on `concepts`
    (default: all 546) with the training pairs of `dataset` (default: the shipped
    examples) at `threshold`, the weights' card)."""
    from vccjax.world.concepts import concept_names
    from vccjax.world.dataset import dataset_for

    names = list(concepts) if concepts is not None else concept_names()
    if not names:
        raise ValueError("no concepts to measure recall on")
    predictor = Predictor(weights)
    ds = dataset_for(names, 0, dataset, progress=False)
    return recall(predictor, names, lambda c: ds.pairs(c, "train"), threshold, fill, filters), predictor.card


def card_record(r: dict, date: str, command: str) -> dict:
    """What a weights card keeps of a recall measured on all the concepts (the card's
    `recall` field): the figures, the concepts missed and how it was measured."""
    return {"concepts": r["concepts"], "recalled": r["recalled"], "recall": r["recall"],
            "threshold": THRESHOLD, "examples": "training pairs of the shipped dataset",
            "mean_extra_arguments": r["mean_extra_arguments"], "missed": r["missed"],
            "date": date, "command": command}
