"""Compression: greedy subroutine discovery (paper, Methods, "The probabilistic model").

Maximise log p(C) + log p(D): the compressed programs C and the dictionary's bodies D
are both encoded by one Markov model fitted (MAP) on them, so a subroutine pays for its
own definition and only earns its place when it is used often enough. One subroutine
is added at a time, the one with the largest gain, until none gains or `cap` is hit.
Candidates are token sequences that occur more than once and keep loops balanced.
"""

from __future__ import annotations

import collections
from collections.abc import Sequence

from search.model import Vocabulary, collection_dl
from vccjax.machine.instructions import OP

_START, _END = OP["loop_start"], OP["loop_end"]


def replace(seq: Sequence[int], pattern: tuple[int, ...], token: int) -> list[int]:
    """Non-overlapping occurrences of `pattern`, left to right, replaced by `token`."""
    out, i, n = [], 0, len(pattern)
    while i < len(seq):
        if tuple(seq[i : i + n]) == pattern:
            out.append(token)
            i += n
        else:
            out.append(seq[i])
            i += 1
    return out


def _balanced(atoms: Sequence[int]) -> bool:
    depth = 0
    for a in atoms:
        depth += (a == _START) - (a == _END)
        if depth < 0 or depth > 1:
            return False
    return depth == 0


def candidates(programs: Sequence[Sequence[int]], vocab: Vocabulary, max_len: int = 12) -> collections.Counter:
    """Sequences of 2..max_len tokens that occur more than once (non-overlapping within a
    program), with balanced loops, and their number of occurrences."""
    count: collections.Counter = collections.Counter()
    for p in programs:
        seen: dict[tuple[int, ...], int] = {}  # pattern -> end of its last counted occurrence
        for i in range(len(p)):
            for n in range(2, min(max_len, len(p) - i) + 1):
                pat = tuple(p[i : i + n])
                if seen.get(pat, -1) <= i:
                    seen[pat] = i + n
                    count[pat] += 1
    return collections.Counter({
        pat: k for pat, k in count.items() if k > 1 and _balanced(vocab.expand(pat))
    })


def compress(
    programs: Sequence[Sequence[int]], vocab: Vocabulary | None = None, *, order: int = 1,
    epsilon: float = 0.1, cap: int = 100, shortlist: int = 64,
) -> tuple[list[list[int]], Vocabulary, list[float]]:
    """Greedy MAP compression of atomic (or already compressed) programs.

    Returns the compressed programs, the vocabulary with the new subroutines, and the
    description length log after each addition (first entry: before any). Each round
    scores exactly the `shortlist` candidates with the largest raw saving
    (occurrences - 1) x (length - 1); the rest cannot beat them by much and would cost
    a full refit each.
    """
    vocab = vocab or Vocabulary()
    progs = [list(p) for p in programs]

    def dl(ps, v):
        return collection_dl(ps + [list(b) for b in v.bodies], v.size, order, epsilon)

    history = [dl(progs, vocab)]
    for _ in range(cap):
        cands = candidates(progs, vocab)
        ranked = sorted(cands, key=lambda p: (-(cands[p] - 1) * (len(p) - 1), p))[:shortlist]
        best = None
        for pat in ranked:
            v2 = vocab.add(pat)
            p2 = [replace(p, pat, vocab.size) for p in progs]
            score = dl(p2, v2)
            if score < history[-1] - 1e-9 and (best is None or score < best[0]):
                best = (score, v2, p2)
        if best is None:
            break
        history.append(best[0])
        vocab, progs = best[1], best[2]
    return progs, vocab, history
