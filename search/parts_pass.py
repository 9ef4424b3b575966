"""Explore-compress's last pass: each concept it missed, searched once more with the model
of everything it found, whole and then in parts, as `vcc learn` learns a new concept.

The iterations stop at `max_iterations` or when one finds nothing new; the programs its
last iteration found never guided a search, and a model fitted on them may already rank
a missed concept within the budget: the pass first searches the missed concepts whole,
in lockstep, as an iteration does. Many that stay missed are two learned concepts
joined ("move all yellow objects down, and all green ones up"): the joined program
ranks far past the budget, while each half, under that model, is among the first few
thousand. Those are then tried with `search.parts.learn_in_parts` (a first part that
brings every example closer to its output, the rest from what it makes, the join
checked on every pair by the reference machine), each part's search a tenth of the
budget and all of them together at most 1.3 budgets. So the pass costs at most 2.3
budgets per missed concept.

Its records carry the iteration number `max_iterations` (past every iteration's),
`last_pass` and `parts` (how many; 0 when found whole); a resume skips the concepts it
has already recorded.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence

from search.chain import Chain
from search.explore import Explorer, Searcher
from search.induce import (Run, Settings, argument_logp, fit_model, generalization, needs_answer, record_of,
                           write_model)
from search.model import MarkovModel, Vocabulary
from search.parts import learn_in_parts, parts_settings
from search.result import Result, rank_of, text_of
from search.task import Task
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
    # fitted on the iterations' programs only: a resumed pass searches with the model its
    # first session wrote, not one that has also seen what the pass found
    before = {c: r for c, r in found.items() if r["iteration"] < it}
    vocab, model = start or fit_model([parse(before[c]["program"]) for c in sorted(before)], settings,
                                      settings.subroutines)
    write_model(run, it, settings, vocab, model)
    missed = [c for c in dict.fromkeys(concepts) if c not in found and c not in run.tried(it)]

    def chain_of(c: str, p: Pairs) -> Chain:
        answer = answers(c) if answers is not None and needs_answer(settings) else None
        return Chain(vocab, model, argument_logp(settings, c, p, answer), settings.delta)

    bar = tqdm(total=len(missed), desc="last pass", disable=not progress, unit="concept")

    def done(c: str, r: Result, parts: int, covered: int) -> None:
        test = None
        if r.found:
            tp = pairs(c, "test")
            test = (generalization(r.program, tp, DEFAULT_CONFIG.tau), len(tp))
        run.append({**record_of(c, it, r, test), "covered": covered, "parts": parts, "last_pass": True,
                    "subroutines": len(vocab.bodies)})
        bar.update()
        bar.set_postfix(found=len(run.found()))

    # whole first, all together in lockstep (as an iteration searches): the model of
    # everything found may already rank a missed concept within the budget
    jobs = [(chain_of(c, train), Task.from_pairs(train)) for c in missed for train in [pairs(c, "train")]]
    whole: dict[str, Result] = {}

    def whole_done(j: int, r: Result) -> None:
        whole[missed[j]] = r
        if r.found:
            done(missed[j], r, 0, r.rank)

    if jobs:
        searcher.search_many(jobs, settings.budget, whole_done)
    if not isinstance(searcher, Searcher):  # a cluster searches many concepts at once, not one by one
        searcher = Explorer(width=1)
    rest = [c for c in missed if not whole[c].found]

    def parts_done(c: str, r: Result, parts: int) -> None:
        w = whole[c]
        done(c, dataclasses.replace(r, programs=w.programs + r.programs, seconds=w.seconds + r.seconds,
                                    compile_seconds=w.compile_seconds), parts, w.budget + r.programs)

    learn_missed(rest, lambda c: pairs(c, "train"), chain_of, searcher, settings.budget, settings.parts, parts_done)
    bar.close()
    new = [r for r in run.records if r["iteration"] == it and r["found"]]
    log(f"last pass: {len(new)} new ({sum(1 for r in new if r['parts'])} in parts), "
        f"{len(run.found())} of {len(set(concepts))} found")


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
    if spelt is None:
        return Result(found=True, program=program, text=program.text(), dl_nats=None, dl_bins=None, rank=None,
                      nodes=0, programs=judged, seconds=seconds, cutoff_bins=0, budget=budget)
    nats, portions = spelt
    bins = chain.program_bins(portions)
    return Result(found=True, program=program, text=text_of(chain, portions), dl_nats=float(nats), dl_bins=bins,
                  rank=rank_of(chain, bins), nodes=0, programs=judged, seconds=seconds, cutoff_bins=0,
                  budget=budget)
