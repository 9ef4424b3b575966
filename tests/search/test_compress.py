"""Compression (search/compress.py): subroutines that lower the description length,
expand back exactly and keep loops balanced; candidates counted against brute force."""

from __future__ import annotations

import itertools

import pytest

from search.compress import candidates, compress, replace
from search.model import Vocabulary, collection_dl
from vccjax.machine.instructions import N_OPS, OP

LS, LE = OP["loop_start"], OP["loop_end"]


def balanced(atoms) -> bool:
    depth = 0
    for a in atoms:
        depth += (a == LS) - (a == LE)
        if not 0 <= depth <= 1:
            return False
    return depth == 0


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
