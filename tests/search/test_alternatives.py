"""Other programs that explain every example (what `vcc learn` asks about): the search
keeps the same best program, and the alternatives it keeps are exactly the fits within
the margin, found here by brute force over every short program."""

from __future__ import annotations

import pytest

from search.arguments import argument_logp, uniform_over
from search.chain import Chain
from search.dfs import Alternatives
from search.explore import Task
from search.model import MarkovModel, Vocabulary
from search.scalar import ScalarExplorer
from vccjax.errors import ProgramSyntaxError
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.instructions import OP
from vccjax.machine.program import Program, check_loop_syntax
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import scenes_match
from vccjax.world.concepts import reference_program
from vccjax.world.dataset import dataset_for

CONCEPT = "remove_bottom_obj"
BUDGET = 4000


@pytest.fixture(scope="module")
def two_pairs():
    return dataset_for([CONCEPT], 0, None, progress=False).pairs(CONCEPT, "train")[:2]


@pytest.fixture(scope="module")
def chain():
    """The model fitted on the 546 reference programs (so that few programs are cheaper than
    the answer); the reference's arguments, but any of the five fixations."""
    from vccjax.world.concepts import all_concepts

    lp = argument_logp("oracle", answer=reference_program(CONCEPT))
    lp[OP["fixate"]] = uniform_over(range(5), "fixate")
    model = MarkovModel.fit([list(p.ops) for p in all_concepts().values()], Vocabulary().size, 1, 0.1)
    return Chain(Vocabulary(), model, lp)


def _explains(program: Program, pairs) -> bool:
    for a, b in pairs:
        m = RefMachine(a).run(program)
        if m.failed or not scenes_match(m.output_scene(), b, DEFAULT_CONFIG.tau):
            return False
    return True


def _every_program_up_to(chain: Chain, limit: int):
    """(program, cost in bins) of every syntactically valid program costing at most
    `limit`, by plain recursion over portions: cost = each token's transition from the
    previous (the end marker first) plus its arguments, plus the transition to the end."""
    out = []

    def grow(portions: list[int], cost: int, last: int) -> None:
        if portions:
            total = cost + int(chain.trans_bins[last, chain.end])
            ops = tuple(op for z in portions for op in chain.ops[z])
            args = tuple(a for z in portions for a in chain.args[z])
            program = Program(ops, args)
            try:
                check_loop_syntax(program)
                if total <= limit:
                    out.append((program, total))
            except ProgramSyntaxError:
                pass
        for z in range(chain.n_portions):
            tok = int(chain.tok[z])
            c = cost + int(chain.trans_bins[last, tok]) + int(chain.argbins[z])
            if c <= limit:
                grow(portions + [z], c, tok)

    grow([], 0, chain.end)
    return out


def test_alternatives_leave_the_best_program_as_it_was(chain, two_pairs):
    task = Task.from_pairs(two_pairs)
    plain = ScalarExplorer().search(chain, task, BUDGET)
    wide = ScalarExplorer().search(chain, task, BUDGET, alternatives=Alternatives(200, 50, 10**6))
    assert plain.found and (wide.text, wide.rank, wide.dl_bins) == (plain.text, plain.rank, plain.dl_bins)
    assert not plain.alternatives and wide.alternatives
    assert wide.programs >= plain.programs


def test_alternatives_are_every_fit_within_the_margin(chain, two_pairs):
    task = Task.from_pairs(two_pairs)
    margin = 200  # bins: 2 nats
    r = ScalarExplorer().search(chain, task, BUDGET, alternatives=Alternatives(margin, 10_000, 10**6))
    assert r.found and r.dl_bins + margin < r.cutoff_bins  # the budget's cutoff does not cut the margin
    brute = {p.text(): c for p, c in _every_program_up_to(chain, r.dl_bins + margin) if _explains(p, two_pairs)}
    assert min(brute.values()) == r.dl_bins and r.program.text() in brute
    kept = [a.program.text() for a in r.alternatives]
    assert sorted(kept) == sorted(t for t in brute if t != r.program.text())
    costs = [brute[t] for t in kept]
    assert costs == sorted(costs)  # cheapest first
    # the two fixations the two pairs cannot tell apart are both there (by hand: the bottom
    # object of each pair's input is also its right-most one)
    texts = {r.program.text(), *kept}
    assert any("fixate(bottom)" in t for t in texts) and any("fixate(right)" in t for t in texts)


def test_keep_and_extra_budget_bound_the_alternatives(chain, two_pairs):
    task = Task.from_pairs(two_pairs)
    few = ScalarExplorer().search(chain, task, BUDGET, alternatives=Alternatives(200, 3, 10**6))
    assert len(few.alternatives) <= 2
    wide = ScalarExplorer().search(chain, task, BUDGET, alternatives=Alternatives(200, 10_000, 10**6))
    assert [a.program.text() for a in few.alternatives] == [a.program.text() for a in wide.alternatives][:2]
    none = ScalarExplorer().search(chain, task, BUDGET, alternatives=Alternatives(200, 10_000, 1))
    plain = ScalarExplorer().search(chain, task, BUDGET)
    assert none.text == plain.text and none.programs <= plain.programs + 256  # one slice at most


def test_the_rival_pass_looks_past_the_budgets_cutoff(chain, two_pairs):
    from search.learn import LearnSettings, alternatives_for, with_rivals

    task = Task.from_pairs(two_pairs)
    plain = ScalarExplorer().search(chain, task, BUDGET)
    from search.chain import cutoff_for_budget

    ends_at_first = int(cutoff_for_budget(chain, BUDGET)[1][plain.dl_bins])  # programs costing at most the first
    first = ScalarExplorer().search(chain, task, ends_at_first)
    assert first.found and first.text == plain.text and first.cutoff_bins == first.dl_bins
    settings = LearnSettings(rival_margin_nats=2.0, rival_budget=BUDGET, max_rivals=10_000)
    r = with_rivals(first, chain, task, settings, ScalarExplorer())
    margin = alternatives_for(chain, settings, BUDGET).margin_bins
    brute = {p.text() for p, _ in _every_program_up_to(chain, first.dl_bins + margin) if _explains(p, two_pairs)}
    kept = sorted(a.program.text() for a in r.alternatives)
    assert kept and kept == sorted(brute - {first.program.text()})  # every rival, all beyond the first's cutoff
    assert (r.text, r.rank, r.dl_bins) == (first.text, first.rank, first.dl_bins) and r.programs > first.programs


def test_rivals_are_kept_one_per_behaviour_the_cheapest_of_each(chain, two_pairs):
    """With a behaviour key, `keep` counts behaviours: for each behaviour but the best's,
    the cheapest fit within the margin (brute force), and nothing that acts like the best."""
    from search.ambiguity import fresh_scenes, outcomes
    from search.result import program_of

    task = Task.from_pairs(two_pairs)
    lp = dict(chain.arg_logp)
    lp[OP["set_color_attn"]] = uniform_over(range(len(lp[OP["set_color_attn"]])), "set_color_attn")
    chain = Chain(chain.vocab, chain.model, lp)  # colours too: more ways to pick an object
    probes = fresh_scenes([a for a, _ in two_pairs], 8, seed=3)

    def key_of(program: Program) -> tuple:
        return tuple(outcomes(program, probes))

    def behaviour(path) -> tuple:
        return key_of(program_of(chain, [int(x) for x in path if x >= 0]))

    margin = 300
    r = ScalarExplorer().search(chain, task, BUDGET, alternatives=Alternatives(margin, 10_000, 10**6, behaviour))
    brute = sorted(((c, p) for p, c in _every_program_up_to(chain, r.dl_bins + margin) if _explains(p, two_pairs)),
                   key=lambda cp: cp[0])
    cheapest: dict[tuple, int] = {}
    for c, p in brute:
        cheapest.setdefault(key_of(p), c)
    best_key = key_of(r.program)
    expected = sorted(c for k, c in cheapest.items() if k != best_key)
    keys = [key_of(a.program) for a in r.alternatives]
    assert len(expected) >= 2 and len(set(keys)) == len(keys) and best_key not in keys
    assert sorted(cheapest[k] for k in keys) == expected  # every other behaviour once
    cost = {p.text(): c for c, p in brute}
    assert [cost[a.program.text()] for a in r.alternatives] == [cheapest[k] for k in keys]  # its cheapest
    # a small `keep` is filled by distinct behaviours, so it reaches past the same-acting variants
    few = ScalarExplorer().search(chain, task, BUDGET, alternatives=Alternatives(margin, 3, 10**6, behaviour))
    assert [key_of(a.program) for a in few.alternatives] == keys[:2]
