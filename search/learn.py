"""Learn one new concept from a user's example pairs: the search of explore-compress,
started from the learned library, and a question back when the examples are ambiguous.

Nothing here reads an answer: arguments come from the argument CNN on the pairs (or
uniform), fixation from the user's hint when given. The search finds the most probable
program under the library's model that explains every pair (as `vcc induce` would). A
second pass then looks for other programs that explain them too (`search.dfs.Alternatives`)
among the programs ranked up to `rival_budget` past the first fit, past the budget's own
cutoff if need be: a rival a little less probable than the first must not be missed because
the first was found near the end of the budget. `search.ambiguity` then tells whether the
rivals behave differently on fresh scenes and which scene to ask about.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence

import numpy as np

from argpred.acted import check_filters
from search.ambiguity import Verdict, fresh_scenes, judge, outcomes
from search.arguments import argument_logp
from search.chain import Chain
from search.dfs import Alternatives
from search.explore import Searcher
from search.model import MarkovModel, Vocabulary
from search.parts import learn_in_parts, parts_settings
from search.result import Alternative, Result, program_of, rank_of, text_of
from search.task import Task
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.program import Program
from vccjax.machine.scene import Scene

LIBRARIES = ("shipped", "uniform")  # or a library file's path


@dataclasses.dataclass(frozen=True)
class LearnSettings:
    budget: int = 500_000  # programs searched for the first fit, at most
    args: str = "predicted"  # or "uniform"
    filters: str = "acted+raised"  # predicted: filter values the pairs rule out dropped, point in raised
    fixate: tuple[str, ...] | None = None  # the teacher's hint: fixate only to these
    library: str = "shipped"  # "shipped", "uniform" (from scratch) or a library file
    rival_margin_nats: float = 6.0  # rivals at most this much less probable than the first
    rival_budget: int = 2_000_000  # programs ranked past the first fit that the rival pass judges
    parts: int = 3  # when nothing fits, learn in up to this many parts (`search.parts`; 1: never)
    max_rivals: int = 32  # distinct behaviours on the probe scenes
    rival_probes: int = 16  # fresh scenes that tell the rival search's behaviours apart
    fresh_scenes: int = 100
    min_scenes: int = 2  # fresh scenes a rival must part on to make the examples ambiguous
    seed: int = 0
    delta: float = 0.01

    def __post_init__(self) -> None:
        if self.args not in ("predicted", "uniform"):
            raise ValueError(f"--args must be predicted or uniform, got {self.args!r}")
        check_filters(self.filters)
        if self.budget < 1:
            raise ValueError(f"--budget must be positive, got {self.budget}")
        if not 1 <= self.parts <= 5:
            raise ValueError(f"--parts must be 1 to 5, got {self.parts}")
        if self.rival_budget < 0 or self.max_rivals < 1 or self.rival_margin_nats < 0 or self.rival_probes < 0:
            raise ValueError("the rival search's budget, margin and count must not be negative")
        if self.fresh_scenes < 1:
            raise ValueError(f"--fresh-scenes must be positive, got {self.fresh_scenes}")


@dataclasses.dataclass
class Learned:
    """What learning reported: the program, the rivals, and the question when ambiguous."""

    result: Result
    library: str  # the library's content sha256, or "uniform"
    verdict: Verdict | None  # None when nothing fits
    scenes: list[Scene]  # the fresh scenes the verdict ran on
    parts: tuple[Program, ...] = ()  # when learned in parts (`search.parts`), each part

    @property
    def found(self) -> bool:
        return self.result.found

    @property
    def program(self) -> Program | None:
        return self.result.program

    @property
    def ambiguous(self) -> bool:
        return bool(self.verdict and self.verdict.ambiguous)

    def rivals(self) -> list[tuple[Program, str, float, int, int]]:
        """(program, as searched, description length in nats, fresh scenes where the first
        runs and it parts from it, fresh scenes where the first fails and it runs) of each
        program that behaves unlike the first."""
        if self.verdict is None:
            return []
        cands, v = self.candidates(), self.verdict
        return [(cands[i][0], cands[i][1], cands[i][2], d, e)
                for i, d, e in zip(v.programs[1:], v.disagree[1:], v.runs_where_first_fails[1:], strict=True)]

    def candidates(self) -> list[tuple[Program, str, float]]:
        r = self.result
        if not r.found:
            return []
        return [(r.program, r.text, r.dl_nats)] + [(a.program, a.text, a.dl_nats) for a in r.alternatives]

    @property
    def query_scene(self) -> Scene | None:
        if self.verdict is None or self.verdict.query is None:
            return None
        return self.scenes[self.verdict.query]


def model_for(library: str) -> tuple[Vocabulary, MarkovModel, str]:
    """(vocabulary, model, name) to start from: the shipped library, a library file, or
    a uniform model over the atoms (from scratch)."""
    if library == "uniform":
        return Vocabulary(), MarkovModel.uniform(Vocabulary().size, 1), "uniform"
    from search.library import load

    lib = load(None if library == "shipped" else library)
    return lib.vocab, lib.model, lib.sha256


def chain_for(pairs: Sequence[tuple[Scene, Scene]], settings: LearnSettings,
              start: tuple[Vocabulary, MarkovModel, str] | None = None) -> tuple[Chain, str]:
    """The search's chain for these pairs: the start model and the argument beliefs."""
    vocab, model, name = start or model_for(settings.library)
    mode = settings.args + ("+fixation" if settings.fixate else "")
    return Chain(vocab, model, argument_logp(mode, pairs, None, settings.fixate, fallback=True,
                                             filters=settings.filters), settings.delta), name


def alternatives_for(chain: Chain, settings: LearnSettings, budget: int,
                     inputs: Sequence[Scene] = ()) -> Alternatives:
    """The rival search's settings; with `inputs`, rivals are told apart by what they do
    on `rival_probes` fresh scenes like them, so that `max_rivals` counts behaviours."""
    margin = int(math.ceil(settings.rival_margin_nats / chain.delta))
    behaviour = None
    probes = fresh_scenes(inputs, settings.rival_probes, settings.seed, DEFAULT_CONFIG) if inputs else []
    if len(probes) >= max(4, settings.rival_probes // 2):  # too few scenes would merge what differs

        def behaviour(path: np.ndarray) -> tuple:
            return tuple(outcomes(program_of(chain, [int(x) for x in path if x >= 0]), probes, DEFAULT_CONFIG))
    return Alternatives(margin, settings.max_rivals, budget, behaviour)


def with_rivals(first: Result, chain: Chain, task: Task, settings: LearnSettings, searcher: Searcher,
                progress: Callable[[int], None] | None = None, inputs: Sequence[Scene] = ()) -> Result:
    """`first` (a finished search's result) with the rivals of a second pass over the
    programs ranked up to `first.rank + rival_budget`, within the margin of the first.

    The depth-first search prunes by its cutoff as it goes, so a cutoff raised after the
    first fit would miss programs in branches already cut: the pass starts over with the
    higher cutoff. The first program stays the answer (the pass finds it again, or one of
    the same cost, which then counts as a rival), unless it came from an earlier question
    (`settle`) and the pass finds a cheaper fit. With the examples' `inputs`, rivals are
    kept one per behaviour (`alternatives_for`)."""
    if not first.found or settings.rival_budget == 0:
        return first
    budget = first.rank + settings.rival_budget
    alternatives = alternatives_for(chain, settings, budget, inputs)
    again = searcher.search(chain, task, budget, progress, alternatives)
    others = [Alternative(again.program, again.text, again.dl_nats)] if again.found else []
    others += list(again.alternatives)
    if again.found and again.dl_bins < first.dl_bins:  # `first` came from a question (`settle`), past the budget
        others[0] = Alternative(first.program, first.text, first.dl_nats)
        first = dataclasses.replace(first, program=again.program, text=again.text, dl_nats=again.dl_nats,
                                    dl_bins=again.dl_bins, rank=again.rank)
    kept = tuple(a for a in others if a.program != first.program)[: settings.max_rivals - 1]
    return dataclasses.replace(first, alternatives=kept, programs=first.programs + again.programs,
                               nodes=first.nodes + again.nodes, seconds=first.seconds + again.seconds,
                               compile_seconds=first.compile_seconds + again.compile_seconds)


def with_each_or_one(result: Result, chain: Chain, pairs: Sequence[tuple[Scene, Scene]],
                     settings: LearnSettings) -> Result:
    """`result` with the learned program's each-or-one variants (`search.each_or_one`:
    "every square" beside "the square") that explain every pair as rivals, first among
    them: the rival pass finds them only within its margin, and a loop is rarely that
    cheap. Not where the rival search is off (`rival_budget` 0)."""
    from search.each_or_one import variants
    from search.induce import generalization

    if not result.found or settings.rival_budget == 0:
        return result
    have = {result.program} | {a.program for a in result.alternatives}
    extra = []
    for v in variants(result.program):
        spelt = None if v in have or generalization(v, pairs, DEFAULT_CONFIG.tau) < len(pairs) \
            else chain.cheapest(v.ops, v.args)
        if spelt is not None:  # it fits every pair, and its arguments are ones the chain believes in
            extra.append(Alternative(v, text_of(chain, spelt[1]), float(spelt[0])))
    if not extra:
        return result
    return dataclasses.replace(result, alternatives=(*extra, *result.alternatives)[: settings.max_rivals - 1])


def verdict_for(result: Result, pairs: Sequence[tuple[Scene, Scene]], settings: LearnSettings
                ) -> tuple[Verdict | None, list[Scene]]:
    if not result.found:
        return None, []
    programs = [result.program] + [a.program for a in result.alternatives]
    nats = [result.dl_nats] + [a.dl_nats for a in result.alternatives]
    return judge(programs, [a for a, _ in pairs], settings.fresh_scenes, settings.seed, settings.min_scenes,
                 DEFAULT_CONFIG, nats)


def settle(searched: Result, chain: Chain, pairs: Sequence[tuple[Scene, Scene]],
           asked: Sequence[Program]) -> Result:
    """The search's result, or the cheapest of the `asked` programs (those a question was
    about) that explains every pair where it is cheaper or the search found nothing.

    A question is asked about programs the rival pass found, up to `rival_budget` past the
    budget; the answer picks among them, so one it keeps must not be lost because a fresh
    search from the pairs stops at the budget's cutoff."""
    from search.induce import generalization

    best = None
    for program in asked:
        spelt = chain.cheapest(program.ops, program.args)
        if spelt is None or (best is not None and spelt[0] >= best[0]):
            continue
        if generalization(program, pairs, DEFAULT_CONFIG.tau) == len(pairs):
            best = spelt
    if best is None or (searched.found and searched.dl_nats <= best[0]):
        return searched
    nats, portions = best
    bins = chain.program_bins(portions)
    return dataclasses.replace(searched, found=True, program=program_of(chain, portions),
                               text=text_of(chain, portions), dl_nats=nats, dl_bins=bins, rank=rank_of(chain, bins))


def from_uniform(searched: Result, pairs: Sequence[tuple[Scene, Scene]], settings: LearnSettings,
                 searcher: Searcher, start: tuple[Vocabulary, MarkovModel, str],
                 progress: Callable[[int], None] | None = None, asked: Sequence[Program] = (),
                 log: Callable[[str], None] | None = None) -> tuple[Result, Chain | None]:
    """`searched` (a search from a library that found nothing) tried again from a uniform
    start over a tenth of the budget: a concept unlike the 546 can lie among a uniform
    model's first programs while the library ranks it far down (it rarely saw the
    sequence). Returns (the result, the uniform chain where that search found it, else
    None); the programs judged add up. A search that started uniform is not repeated."""
    if searched.found or start[2] == "uniform":
        return searched, None
    uniform = model_for("uniform")
    chain = chain_for(pairs, settings, uniform)[0]
    if log:
        log(f"nothing within the budget from the library: the first {max(1, settings.budget // 10):,} "
            "programs from a uniform start")
    t0 = time.perf_counter()
    got = settle(searcher.search(chain, Task.from_pairs(pairs), max(1, settings.budget // 10), progress),
                 chain, pairs, asked)
    got = dataclasses.replace(got, programs=searched.programs + got.programs,
                              seconds=searched.seconds + time.perf_counter() - t0)
    return (got, chain) if got.found else (dataclasses.replace(searched, programs=got.programs,
                                                                seconds=got.seconds), None)


def in_parts(searched: Result, pairs: Sequence[tuple[Scene, Scene]], settings: LearnSettings, searcher: Searcher,
             start: tuple[Vocabulary, MarkovModel, str] | None = None,
             log: Callable[[str], None] | None = None) -> tuple[Result, tuple[Program, ...]]:
    """`searched` (a search that found nothing) completed in parts when it can be
    (`search.parts`: each part's search covers a tenth of the budget, all of them together
    at most 1.3 budgets), with the parts. The program's description length and rank
    are those of its cheapest spelling under the chain of the whole pairs (or, where that
    chain rules out an argument a part uses, under the same model with uniform arguments).
    With a rival budget, the other joins that fit every pair come back as the result's
    alternatives."""
    if searched.found or settings.parts < 2:
        return searched, ()
    start = start or model_for(settings.library)
    t0 = time.perf_counter()
    got, judged = learn_in_parts(pairs, lambda p: chain_for(p, settings, start)[0], searcher,
                                 parts_settings(settings.budget, settings.parts,
                                                rivals=settings.max_rivals - 1 if settings.rival_budget else 0),
                                 log=log)
    searched = dataclasses.replace(searched, programs=searched.programs + judged,
                                   seconds=searched.seconds + time.perf_counter() - t0)
    if got is None:
        return searched, ()
    chain, nats, portions = _spelt(got.program, pairs, settings, start)
    if chain is None:  # broken syntax cannot come out of joined parts; kept as a guard
        return searched, ()
    bins = chain.program_bins(portions)
    rank = rank_of(chain, bins)
    rivals = tuple(Alternative(p, text_of(c, z), n) for p in got.rivals
                   for c, n, z in [_spelt(p, pairs, settings, start)] if c is not None)
    return dataclasses.replace(searched, found=True, program=got.program, text=text_of(chain, portions),
                               dl_nats=nats, dl_bins=bins, rank=rank, alternatives=rivals), got.parts


def _spelt(program: Program, pairs: Sequence[tuple[Scene, Scene]], settings: LearnSettings,
           start: tuple[Vocabulary, MarkovModel, str]) -> tuple[Chain | None, float, list[int]]:
    """(chain, nats, portions) of the program's cheapest spelling under the pairs' chain,
    or under the same model with uniform arguments where that chain rules out an argument
    the program uses; (None, inf, []) where neither can spell it."""
    for chain in (chain_for(pairs, settings, start)[0],
                  chain_for(pairs, dataclasses.replace(settings, args="uniform", fixate=None), start)[0]):
        spelt = chain.cheapest(program.ops, program.args)
        if spelt is not None:
            return chain, spelt[0], spelt[1]
    return None, math.inf, []


def learn(pairs: Sequence[tuple[Scene, Scene]], settings: LearnSettings, searcher: Searcher | None = None,
          progress: Callable[[int], None] | None = None, asked: Sequence[Program] = (),
          log: Callable[[str], None] | None = None) -> Learned:
    """Learn a program for `pairs` (at least one), and judge the rivals found beside it.
    `asked`: the programs an earlier question was about, when `pairs` holds its answer.
    When nothing fits, the program is learned in parts (`in_parts`); its rivals are then
    the other joins of parts that fit every pair (the rival pass would start at the
    program's rank, past any rival budget)."""
    if not pairs:
        raise ValueError("learning needs at least one example pair")
    start = model_for(settings.library)
    chain, name = chain_for(pairs, settings, start)
    if searcher is None:
        from search.explore import Explorer

        searcher = Explorer(width=1)
    task = Task.from_pairs(pairs)
    first = settle(searcher.search(chain, task, settings.budget, progress), chain, pairs, asked)
    first, uniform = from_uniform(first, pairs, settings, searcher, start, progress, asked, log)
    if uniform is not None:
        chain, name = uniform, "uniform"
    first, parts = in_parts(first, pairs, settings, searcher, start, log)
    result = first if parts else with_rivals(first, chain, task, settings, searcher, progress, [a for a, _ in pairs])
    result = with_each_or_one(result, chain, pairs, settings)
    verdict, scenes = verdict_for(result, pairs, settings)
    return Learned(result, name, verdict, scenes, parts)
