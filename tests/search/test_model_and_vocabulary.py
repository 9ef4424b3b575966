"""The program model (search/model.py): Markov fits, description lengths and the
vocabulary of atoms and subroutines, checked against hand computations."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import logsumexp

from search.model import MarkovModel, Vocabulary, collection_dl, transition_counts
from vccjax.machine.instructions import N_OPS, NAMES, OP


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
