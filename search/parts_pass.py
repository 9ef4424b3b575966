"""Explore-compress's last pass: each concept it missed, learned in parts with the model
of everything it found.

Many concepts the whole search misses are two learned ones joined ("move all yellow
objects down, and all green ones up"): the joined program ranks far past the budget,
while each half, under a model fitted on the programs found, is among the first few
thousand. After the iterations end, this pass tries every concept still missed with
`search.parts.learn_in_parts` (a first part that brings every example closer to its
output, then the rest from what it makes, the join checked on every pair by the
reference machine), each part's search a tenth of the budget and all of them together
at most the budget again: one more iteration's worth of search per missed concept.

Its records carry the iteration number `max_iterations` (past every iteration's) and
`parts` (how many); a resume skips the concepts it has already tried.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

from search.chain import Chain
from search.explore import Explorer, Searcher
from search.induce import (Run, Settings, argument_logp, fit_model, generalization, needs_answer, record_of,
                           write_model)
from search.model import MarkovModel, Vocabulary
from search.parts import PartsSettings, join_nats, learn_in_parts
from search.result import Result, text_of
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.program import Program, parse
from vccjax.machine.scene import Scene

Pairs = Sequence[tuple[Scene, Scene]]


def parts_pass(run: Run, concepts: Sequence[str], pairs: Callable[[str, str], Pairs], settings: Settings,
               searcher: object, answers: Callable[[str], Program] | None,
               start: tuple[Vocabulary, MarkovModel] | None, progress: bool, log: Callable[[str], None]) -> None:
    """The pass over the run's missed concepts (`settings.parts` parts at most), with the
    model fitted on every program the run found (with subroutines when the settings
    allow them), or the run's start model for a one-pass run. Written as
    `model-{max_iterations}.json`; each concept's record as it is known."""
    from tqdm import tqdm

    it = settings.max_iterations
    found = run.found()
    vocab, model = start or fit_model([parse(found[c]["program"]) for c in sorted(found)], settings,
                                      settings.subroutines)
    write_model(run, it, settings, vocab, model)
    missed = [c for c in dict.fromkeys(concepts) if c not in found and c not in run.tried(it)]
    if not isinstance(searcher, Searcher):  # a cluster searches many concepts at once, not one
        searcher = Explorer(width=1)

    def chain_of(c: str, p: Pairs) -> Chain:
        answer = answers(c) if answers is not None and needs_answer(settings) else None
        return Chain(vocab, model, argument_logp(settings, c, p, answer), settings.delta)

    bar = tqdm(total=len(missed), desc="in parts", disable=not progress, unit="concept")

    def done(c: str, r: Result, parts: int) -> None:
        test = None
        if r.found:
            tp = pairs(c, "test")
            test = (generalization(r.program, tp, DEFAULT_CONFIG.tau), len(tp))
        run.append({**record_of(c, it, r, test), "covered": r.programs, "parts": parts,
                    "subroutines": len(vocab.bodies)})
        bar.update()
        bar.set_postfix(found=len(run.found()))

    learn_missed(missed, lambda c: pairs(c, "train"), chain_of, searcher, settings.budget, settings.parts, done)
    bar.close()
    new = sum(1 for r in run.records if r["iteration"] == it and r["found"])
    log(f"in parts: {new} new, {len(run.found())} of {len(set(concepts))} found")


def parts_settings(budget: int, max_parts: int) -> PartsSettings:
    """A part's search a tenth of the budget; all parts of a concept at most the budget."""
    return PartsSettings(max_parts=max_parts, budget=max(1, budget // 10), allowance=budget)


def learn_missed(concepts: Sequence[str], pairs: Callable[[str], Pairs],
                 chain_of: Callable[[str, Pairs], Chain], searcher: Searcher, budget: int, max_parts: int,
                 done: Callable[[str, Result, int], None]) -> None:
    """Each concept learned in parts where it can be: `chain_of(concept, pairs)` is the
    search's chain for a set of its pairs (its arguments believed from them);
    `done(concept, result, parts)` is told of each, found or not (parts 0 when not)."""
    settings = parts_settings(budget, max_parts)
    for c in concepts:
        train = pairs(c)
        t0 = time.perf_counter()
        got, judged = learn_in_parts(train, lambda p, c=c: chain_of(c, p), searcher, settings)
        seconds = time.perf_counter() - t0
        if got is None:
            done(c, _missed(budget, judged, seconds), 0)
        else:
            done(c, _learned(chain_of(c, train), got.program, budget, judged, seconds), len(got.parts))


def _missed(budget: int, judged: int, seconds: float) -> Result:
    return Result(found=False, program=None, text=None, dl_nats=None, dl_bins=None, rank=None, nodes=0,
                  programs=judged, seconds=seconds, cutoff_bins=0, budget=budget)


def _learned(chain: Chain, program: Program, budget: int, judged: int, seconds: float) -> Result:
    """The joined program as a result: its description length and rank those of its
    cheapest spelling under the whole pairs' chain (None where that chain cannot spell an
    argument a part's own pairs believed in)."""
    spelt = chain.cheapest(program.ops, program.args)
    nats = join_nats(chain, program)
    text, bins, rank = program.text(), None, None
    if spelt is not None:
        portions = spelt[1]
        text = text_of(chain, portions)
        bins = chain.program_bins(portions)
        rank = int(chain.count_table(budget=2**62, max_bins=bins)[bins - 1]) + 1 if bins > 0 else 1
    return Result(found=True, program=program, text=text, dl_nats=None if spelt is None else nats, dl_bins=bins,
                  rank=rank, nodes=0, programs=judged, seconds=seconds, cutoff_bins=0, budget=budget)

