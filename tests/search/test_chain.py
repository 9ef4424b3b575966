"""The per-concept chain (search/chain.py): its syntax automaton against check_loop_syntax,
and its count table and costs against brute-force enumeration."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from search.chain import (
    NOT_STARTED,
    OUTSIDE,
    Chain,
    atom_syntax,
    cutoff_for_budget,
    uniform_args,
)
from search.model import MarkovModel, Vocabulary
from vccjax.errors import ProgramSyntaxError
from vccjax.machine.instructions import N_OPS, NAMES, OP, arg_domain
from vccjax.machine.program import Program, check_loop_syntax

LS = OP["loop_start"]


# ---- the chain: syntax automaton -----------------------------------------------------------


def _walk(chain: Chain, ops) -> int:
    s = NOT_STARTED
    for a in ops:
        s = int(chain.next_syn[a, s])
        if s < 0:
            return -1
    return s


def _valid(ops, complete: bool) -> bool:
    if not ops or ops[0] != OP["scene_parse"] or OP["scene_parse"] in ops[1:]:
        return False
    try:
        check_loop_syntax(Program(tuple(ops), tuple(0 for _ in ops)), complete=complete)
    except ProgramSyntaxError:
        return False
    return True


def test_syntax_automaton_agrees_with_check_loop_syntax():
    chain = Chain(Vocabulary(), MarkovModel.uniform(N_OPS), uniform_args(), 0.05)
    rng = np.random.default_rng(1234)
    special = [OP[n] for n in ("loop_start", "loop_end", "top_down_attend", "next_object",
                               "set_shape_attn", "set_color_attn", "reset_attn", "scene_parse")]
    weights = np.ones(N_OPS)
    weights[special] = 6.0
    weights[OP["scene_parse"]] = 1.0
    weights /= weights.sum()
    accepted = rejected = prefixes = 0
    for _ in range(2000):
        n = int(rng.integers(1, 11))
        ops = [int(x) for x in rng.choice(N_OPS, size=n, p=weights)]
        if rng.random() < 0.85:
            ops[0] = OP["scene_parse"]
        final = _walk(chain, ops)
        ok = final == OUTSIDE
        assert ok == _valid(ops, complete=True), [NAMES[a] for a in ops]
        # a prefix the automaton lets continue is exactly a valid incomplete program
        assert (final >= 0) == _valid(ops, complete=False), [NAMES[a] for a in ops]
        accepted += ok
        rejected += not ok
        prefixes += final > OUTSIDE
    assert accepted > 200 and rejected > 200 and prefixes > 100


def test_next_syn_of_subroutines_composes_atoms(compressed):
    _, vocab, _ = compressed
    chain = Chain(vocab, MarkovModel.uniform(vocab.size), uniform_args(), 0.05)
    for t in range(vocab.size):
        for s in range(chain.next_syn.shape[1]):
            cur = s
            for a in vocab.atoms(t):
                cur = atom_syntax(a, cur)
                if cur < 0:
                    break
            assert chain.next_syn[t, s] == cur


# ---- the chain: exact counting --------------------------------------------------------------


def _oracle_args() -> dict[int, np.ndarray]:
    """set_color_attn: red and green equally likely (two portions of one cost class), blue
    less, yellow excluded; fixate: one value; other arg-taking ops excluded."""
    with np.errstate(divide="ignore"):
        color = np.log([0.45, 0.45, 0.1, 0.0])
    fix = np.full(5, -np.inf)
    fix[2] = 0.0
    return {OP["set_color_attn"]: color, OP["fixate"]: fix}


def _chain(kind: str, reference_ops, compressed) -> Chain:
    if kind == "atoms":
        vocab = Vocabulary()
        model = MarkovModel.fit(reference_ops, vocab.size, 1, 0.1)
    else:
        progs, vocab, _ = compressed
        model = MarkovModel.fit(progs + [list(b) for b in vocab.bodies], vocab.size, 1, 0.1)
    return Chain(vocab, model, _oracle_args(), 0.05)


def _enumerate(chain: Chain, bound: int):
    """Every syntax-valid complete portion sequence of cost <= bound (no min_rest pruning),
    and every prefix visited with the cheapest completion found below it."""
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 5000))
    tok, tb, ab, ns, end = chain.tok, chain.trans_bins, chain.argbins, chain.next_syn, chain.end
    programs: list[tuple[tuple[int, ...], int]] = []
    nodes: list[tuple[int, int, int, float]] = []  # last, syn, cost, cheapest completion

    def dfs(last: int, syn: int, cost: int, path: list[int]) -> float:
        best = math.inf
        if syn == OUTSIDE:
            c = cost + int(tb[last, end])
            if c <= bound:
                programs.append((tuple(path), c))
                best = c - cost
        nxt = ns[tok, syn]
        cc = cost + tb[last, tok] + ab
        for z in np.nonzero((nxt >= 0) & (cc <= bound))[0]:
            path.append(int(z))
            r = dfs(int(tok[z]), int(nxt[z]), int(cc[z]), path)
            path.pop()
            best = min(best, r + int(cc[z]) - cost)
        nodes.append((last, syn, cost, best))
        return best

    dfs(end, NOT_STARTED, 0, [])
    return programs, nodes


@pytest.mark.parametrize("kind", ["atoms", "compressed"])
def test_count_table_is_exact(kind, reference_ops, compressed):
    chain = _chain(kind, reference_ops, compressed)
    budget = 5000
    cutoff, table = cutoff_for_budget(chain, budget)
    assert cutoff == len(table) - 1
    assert table[-1] >= budget and (cutoff == 0 or table[-2] < budget)
    assert np.all(np.diff(table) >= 0)
    programs, nodes = _enumerate(chain, cutoff)
    costs = np.array([c for _, c in programs])
    brute = np.array([(costs <= b).sum() for b in range(cutoff + 1)])
    np.testing.assert_array_equal(table, brute)
    assert len({p for p, _ in programs}) == len(programs)
    # the chain has the structure the test means to exercise
    assert any(len(chain.ops[z]) > 1 for p, _ in programs for z in p) or kind == "atoms"
    assert any(LS in chain.ops[z] for p, _ in programs for z in p)

    for portions, cost in programs:
        assert chain.program_bins(list(portions)) == cost
        ops = [a for z in portions for a in chain.ops[z]]
        assert _valid(ops, complete=True)
        nats = chain.program_nats(list(portions))
        # each transition and each argument's cost is rounded up by less than one bin
        parts = 1 + sum(1 + sum(1 for a in chain.ops[z] if arg_domain(NAMES[a])) for z in portions)
        assert nats <= cost * chain.delta + 1e-6
        assert cost * chain.delta < nats + parts * chain.delta + 1e-6

    # min_rest: a lower bound on every completion, and the cheapest one where it is in reach
    for last, syn, cost, best in nodes:
        r = int(chain.min_rest[last, syn])
        assert r <= best
        if best < math.inf:
            assert r == best
        else:
            assert cost + r > cutoff
