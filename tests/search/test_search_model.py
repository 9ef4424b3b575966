"""The program model (search/model.py), compression (search/compress.py) and the
per-concept chain (search/chain.py): properties checked against hand computations and
brute force."""

from __future__ import annotations

import itertools
import math
import sys

import numpy as np
import pytest
from scipy.special import logsumexp

from search.chain import (
    NOT_STARTED,
    OUTSIDE,
    Chain,
    atom_syntax,
    cutoff_for_budget,
    uniform_args,
)
from search.compress import candidates, compress, replace
from search.model import MarkovModel, Vocabulary, collection_dl, transition_counts
from vccjax.world.concepts import all_concepts
from vccjax.errors import ProgramSyntaxError
from vccjax.machine.instructions import N_OPS, NAMES, OP, arg_domain
from vccjax.machine.program import Program, check_loop_syntax

LS, LE = OP["loop_start"], OP["loop_end"]


@pytest.fixture(scope="module")
def reference_ops() -> list[list[int]]:
    return [list(p.ops) for p in all_concepts().values()]


@pytest.fixture(scope="module")
def compressed(reference_ops):
    return compress(reference_ops, order=1, epsilon=0.1, cap=5)


def balanced(atoms) -> bool:
    depth = 0
    for a in atoms:
        depth += (a == LS) - (a == LE)
        if not 0 <= depth <= 1:
            return False
    return depth == 0


# ---- MarkovModel ------------------------------------------------------------------------


@pytest.mark.parametrize("order", [0, 1])
@pytest.mark.parametrize("epsilon", [0.01, 0.1, 1.0])
def test_fit_rows_are_distributions(reference_ops, order, epsilon):
    m = MarkovModel.fit(reference_ops, N_OPS, order, epsilon)
    assert m.logp.shape == (N_OPS + 1, N_OPS + 1)
    assert m.end == N_OPS and m.order == order and m.epsilon == epsilon
    np.testing.assert_allclose(logsumexp(m.logp, axis=1), 0.0, atol=1e-12)
    assert np.all(np.isfinite(m.logp))  # smoothing rules nothing out


def test_fit_map_smoothing_by_hand():
    # tokens 0, 1; end marker 2. Transitions: end->0 twice, 0->1, 1->end, 0->end.
    seqs = [[0, 1], [0]]
    eps = 0.5
    counts = transition_counts(seqs, 2)
    expected_counts = np.array([[0, 1, 1], [0, 0, 1], [2, 0, 0]], float)
    np.testing.assert_array_equal(counts, expected_counts)
    m = MarkovModel.fit(seqs, 2, order=1, epsilon=eps)
    p = np.exp(m.logp)
    # row 0: counts (0, 1, 1), total 2; 3 outcomes
    assert p[0, 1] == pytest.approx((1 + 0.5) / (2 + 1.5))
    assert p[0, 0] == pytest.approx(0.5 / 3.5)
    assert p[0, 2] == pytest.approx(1.5 / 3.5)
    # row 1: counts (0, 0, 1)
    assert p[1, 0] == pytest.approx(0.5 / 2.5)
    assert p[1, 2] == pytest.approx(1.5 / 2.5)
    # start (row end): counts (2, 0, 0)
    assert p[2, 0] == pytest.approx(2.5 / 3.5)
    assert p[2, 1] == pytest.approx(0.5 / 3.5)

    m0 = MarkovModel.fit(seqs, 2, order=0, epsilon=eps)
    p0 = np.exp(m0.logp)
    # order 0: unigram over the targets of all transitions: 0 twice, 1 once, end twice
    for row in p0:
        np.testing.assert_allclose(row, [2.5 / 6.5, 1.5 / 6.5, 2.5 / 6.5])


def test_fit_order0_rows_equal(reference_ops):
    m = MarkovModel.fit(reference_ops, N_OPS, order=0, epsilon=0.1)
    for row in m.logp:
        np.testing.assert_allclose(row, m.logp[0], rtol=0, atol=1e-12)
    m1 = MarkovModel.fit(reference_ops, N_OPS, order=1, epsilon=0.1)
    assert not np.allclose(m1.logp, m1.logp[0])  # order 1 does condition


def test_fit_rejects_other_orders():
    with pytest.raises(ValueError):
        MarkovModel.fit([[0]], 2, order=2)


def test_uniform_model():
    m = MarkovModel.uniform(5)
    np.testing.assert_allclose(m.logp, -math.log(6))
    assert m.description_length([[0, 1]]) == pytest.approx(3 * math.log(6))


@pytest.mark.parametrize("order", [0, 1])
def test_description_length_is_sum_of_transition_costs(reference_ops, order):
    seqs = reference_ops[:80]
    m = MarkovModel.fit(reference_ops, N_OPS, order, 0.1)  # fitted on more than it scores
    end = N_OPS
    total = 0.0
    for s in seqs:
        prev = end  # start = from the end marker
        for t in s:
            total -= m.logp[prev, t]
            prev = t
        total -= m.logp[prev, end]  # and the end
    assert m.description_length(seqs) == pytest.approx(total, rel=1e-12)
    assert collection_dl(seqs, N_OPS, order, 0.1) == pytest.approx(
        MarkovModel.fit(seqs, N_OPS, order, 0.1).description_length(seqs), rel=1e-12)


def test_description_length_by_hand():
    seqs = [[0, 1], [0]]
    m = MarkovModel.fit(seqs, 2, order=1, epsilon=0.5)
    expected = -(2 * math.log(2.5 / 3.5) + math.log(1.5 / 3.5) + math.log(1.5 / 2.5) + math.log(1.5 / 3.5))
    assert m.description_length(seqs) == pytest.approx(expected)


# ---- Vocabulary ---------------------------------------------------------------------------


def test_vocabulary_atoms_and_expand():
    v = Vocabulary().add([OP["scene_parse"], OP["top_down_attend"]])
    v = v.add([N_OPS, OP["grab_object"], N_OPS])
    assert v.size == N_OPS + 2 and v.end == N_OPS + 2
    assert v.atoms(OP["fixate"]) == (OP["fixate"],)
    assert v.atoms(N_OPS + 1) == (OP["scene_parse"], OP["top_down_attend"], OP["grab_object"],
                                  OP["scene_parse"], OP["top_down_attend"])
    assert v.expand([N_OPS, OP["fixate"]]) == (OP["scene_parse"], OP["top_down_attend"], OP["fixate"])
    assert v.name(N_OPS + 1) == "sub1" and v.name(3) == NAMES[3]


def test_vocabulary_json_round_trip(compressed):
    _, vocab, _ = compressed
    assert len(vocab.bodies) > 0
    js = vocab.to_json()
    assert all(isinstance(n, str) for b in js for n in b)
    back = Vocabulary.from_json(js)
    assert back == vocab
    assert back.to_json() == js
    hand = Vocabulary().add([OP["loop_start"], OP["next_object"]]).add([N_OPS, OP["loop_end"], N_OPS])
    assert Vocabulary.from_json(hand.to_json()) == hand


@pytest.mark.parametrize("bodies", [
    [["scene_parse", "not_an_op"]],
    [["sub0", "grab_object"]],  # refers to itself
    [["scene_parse", "grab_object"], ["sub1", "grab_object"]],  # forward reference
    [["scene_parse", "sub"]],
    [["scene_parse", "subx"]],
])
def test_vocabulary_from_json_refuses_unknown_tokens(bodies):
    with pytest.raises(ValueError):
        Vocabulary.from_json(bodies)


# ---- compression --------------------------------------------------------------------------


def test_compress_history_strictly_decreasing(compressed, reference_ops):
    progs, vocab, history = compressed
    assert len(history) == len(vocab.bodies) + 1
    assert len(vocab.bodies) == 5  # the reference programs have far more than 5 useful subroutines
    assert all(b < a for a, b in itertools.pairwise(history))
    assert history[0] == pytest.approx(collection_dl(reference_ops, N_OPS, 1, 0.1))
    # the last entry is the DL of what was returned (programs plus bodies, one model)
    assert history[-1] == pytest.approx(
        collection_dl(progs + [list(b) for b in vocab.bodies], vocab.size, 1, 0.1))


def test_compress_expands_back_exactly(compressed, reference_ops):
    progs, vocab, _ = compressed
    assert len(progs) == len(reference_ops)
    for p, orig in zip(progs, reference_ops):
        assert vocab.expand(p) == tuple(orig)
        assert all(0 <= t < vocab.size for t in p)
    assert sum(map(len, progs)) < sum(map(len, reference_ops))
    used = {t for p in progs for t in p if t >= N_OPS} | {t for b in vocab.bodies for t in b if t >= N_OPS}
    assert used == set(range(N_OPS, vocab.size))  # every subroutine is used somewhere


def test_compress_bodies_balanced(compressed):
    _, vocab, _ = compressed
    for i, b in enumerate(vocab.bodies):
        assert len(b) >= 2
        assert all(t < N_OPS + i for t in b)  # only earlier subroutines
        assert balanced(vocab.atoms(N_OPS + i)), vocab.to_json()[i]


def test_compress_cap_zero_and_nothing_to_gain():
    progs, vocab, hist = compress([[1, 2, 3]], cap=10)
    assert progs == [[1, 2, 3]] and vocab.bodies == () and len(hist) == 1
    progs, vocab, hist = compress([[1, 2, 3, 4]] * 30, cap=0)
    assert vocab.bodies == () and len(hist) == 1


def test_compress_finds_the_obvious_subroutine():
    body = [OP["scene_parse"], OP["set_color_attn"], OP["top_down_attend"], OP["grab_object"]]
    programs = [body + [OP["fixate"] + (i % 3)] for i in range(40)]
    # order 0 pays per token, so the shared 4-token prefix is worth a subroutine
    progs, vocab, hist = compress(programs, order=0, cap=1)
    assert vocab.bodies == (tuple(body),)
    assert all(p == [N_OPS, OP["fixate"] + (i % 3)] for i, p in enumerate(progs))
    assert hist[1] < hist[0]
    # order 1 already predicts the deterministic chain almost for free: no gain, no subroutine
    progs, vocab, hist = compress(programs, order=1, cap=1)
    assert vocab.bodies == () and progs == programs and len(hist) == 1


def test_candidates_need_two_occurrences():
    c = candidates([[1, 2, 3, 4], [1, 2, 5]], Vocabulary())
    assert c[(1, 2)] == 2
    for pat in [(2, 3), (3, 4), (1, 2, 3), (2, 5), (1, 2, 5)]:
        assert pat not in c
    # overlapping occurrences within one program count once
    assert (1, 1) not in candidates([[1, 1, 1]], Vocabulary())
    assert candidates([[1, 1, 1, 1]], Vocabulary())[(1, 1)] == 2
    # unbalanced loops are never candidates, also through a subroutine's expansion
    g = OP["grab_object"]
    assert (LS, g) not in candidates([[LS, g], [LS, g]], Vocabulary())
    v = Vocabulary().add([LS, g])
    assert (N_OPS, LE) in candidates([[N_OPS, LE], [N_OPS, LE]], v)
    assert (N_OPS, g) not in candidates([[N_OPS, g], [N_OPS, g]], v)


def test_candidates_counts_by_brute_force(reference_ops):
    progs = reference_ops[:60]
    cands = candidates(progs, Vocabulary())
    patterns = {tuple(p[i:i + n]) for p in progs for i in range(len(p)) for n in range(2, 13)
                if i + n <= len(p)}
    for pat in patterns:
        # greedy non-overlapping occurrences, left to right, summed over programs
        k = sum((len(p) - len(replace(p, pat, -1))) // (len(pat) - 1) for p in progs)
        if k > 1 and balanced(pat):
            assert cands[pat] == k, pat
        else:
            assert pat not in cands, pat
    assert all(k > 1 for k in cands.values())


def test_replace_non_overlapping_left_to_right():
    assert replace([1, 1, 1], (1, 1), 9) == [9, 1]
    assert replace([1, 1, 1, 1], (1, 1), 9) == [9, 9]
    assert replace([1, 2, 1, 2, 1], (1, 2), 9) == [9, 9, 1]
    assert replace([2, 1, 2, 1, 2], (1, 2), 9) == [2, 9, 9]
    assert replace([1, 2, 1, 2, 1], (2, 1), 9) == [1, 9, 9]
    assert replace([1, 2, 1, 2], (1, 2, 1), 9) == [9, 2]
    assert replace([], (1, 2), 9) == []
    assert replace([3, 4], (1, 2), 9) == [3, 4]
    assert replace([1], (1, 2), 9) == [1]


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
