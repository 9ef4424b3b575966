"""Rounds filled from several frames (`search.dfs._fill`): the search still covers every
program under the cutoff once, counts the budget exactly and finds the cheapest program,
whatever the frame and slice sizes; and a subroutine longer than one call's atom columns
is stepped in several calls as in one."""

from __future__ import annotations

import pytest

import search.dfs as dfs
from search.chain import NOT_STARTED, Chain, cutoff_for_budget, uniform_args
from search.explore import Explorer, Task
from search.model import MarkovModel, Vocabulary
from search.scalar import ScalarBackend, ScalarExplorer
from vccjax.world.dataset import Dataset, build_dataset

NEVER = "swap_locations"  # 23 instructions: never found under these budgets
SHORT = "remove_bottom_obj"


@pytest.fixture(scope="module")
def ds(tmp_path_factory):
    out = tmp_path_factory.mktemp("ds")
    build_dataset(out, [NEVER, SHORT], seed=0, progress=False)
    return Dataset(out)


def _chain() -> Chain:
    v = Vocabulary()
    return Chain(v, MarkovModel.uniform(v.size), uniform_args())


def _nodes_by_brute_force(chain: Chain, task: Task, cutoff: int) -> tuple[int, int]:
    """Children whose cheapest completion costs less than / at most `cutoff`, grown from
    every prefix that runs on all examples and may still complete: a plain recursion, one
    prefix at a time (a child's bound is never below its parent's)."""
    below = at_most = 0

    def grow(machines, last, syntax, cost, depth):
        nonlocal below, at_most
        for z in range(chain.n_portions):
            t = int(chain.tok[z])
            nxt = int(chain.next_syn[t, syntax])
            c = cost + int(chain.trans_bins[last, t] + chain.argbins[z])
            if nxt < 0 or c + int(chain.min_rest[t, nxt]) > cutoff:
                continue
            at_most += 1
            below += c + int(chain.min_rest[t, nxt]) < cutoff
            children = [m.clone() for m in machines]
            for m in children:
                for op, arg in zip(chain.ops[z], chain.args[z], strict=True):
                    m.step(op, arg)
            if not any(m.failed for m in children) and depth + 1 < dfs.MAX_PORTIONS:
                grow(children, t, nxt, c, depth + 1)

    grow(ScalarBackend().root_states(task)[0], chain.end, NOT_STARTED, 0, 0)
    return below, at_most


def test_filled_rounds_cover_every_program_under_the_cutoff_once(ds, monkeypatch):
    chain, task, budget = _chain(), Task.from_pairs(ds.pairs(NEVER, "train")), 3000
    combined = []
    fill = dfs._fill

    def recording(*a):
        out = fill(*a)
        combined.append(len(out))
        return out

    monkeypatch.setattr(dfs, "_fill", recording)
    r = ScalarExplorer(chunk=4, slice_size=16).search(chain, task, budget)
    assert not r.found and 0 < r.programs <= budget  # programs that ran on every example, within the budget
    assert max(combined) > 1  # some rounds took children of several frames
    b_star, counts = cutoff_for_budget(chain, budget)
    below, at_most = _nodes_by_brute_force(chain, task, b_star)
    # every child below b* is run once; those at b* until the budget is spent, which the
    # programs that ran (most fail) do not reach here: so every child at b* too
    assert below < at_most and below <= r.nodes <= at_most
    if r.programs < budget - int(counts[b_star - 1]):
        assert r.nodes == at_most


def test_the_cheapest_program_is_found_whatever_the_frame_and_slice_sizes(ds):
    chain, task = _chain(), Task.from_pairs(ds.pairs(SHORT, "train"))
    small = Explorer(chunk=4, slice_size=16).search(chain, task, 20_000)
    large = ScalarExplorer().search(chain, task, 20_000)
    assert small.found and (small.rank, small.dl_bins) == (large.rank, large.dl_bins)


def test_subroutines_longer_than_a_calls_atom_columns_search_as_the_scalar_search(ds, monkeypatch):
    import search.jax_backend as jb
    from search.induce import Settings, argument_logp
    from search.library import load

    lib = load(None)  # the shipped library: subroutines of several atoms
    chain = Chain(lib.vocab, lib.model, argument_logp(Settings(args="oracle"), SHORT))
    assert chain.op_mat.shape[1] > 2
    monkeypatch.setattr(jb, "ATOM_COLUMNS", 2)  # a portion of 3 or more atoms takes two calls or more
    task = Task.from_pairs(ds.pairs(SHORT, "train"))
    a = Explorer().search(chain, task, 5000)
    b = ScalarExplorer().search(chain, task, 5000)
    assert a.found and (a.text, a.rank, a.nodes, a.programs) == (b.text, b.rank, b.nodes, b.programs)
