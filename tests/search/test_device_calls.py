"""How a batch's rows become device calls (`search.device_calls`): bucket covers, pieces
dealt out to several devices, every row run once on the device its piece went to."""

from __future__ import annotations

import itertools

import jax
import numpy as np
import pytest

from search.device_calls import CALL_ROWS, MIN_SHARE, DeviceCalls, dealt_pieces, piece_sizes

BUCKETS = (16, 64, 256)


def _brute_cover_cost(n: int, buckets: tuple[int, ...]) -> int:
    """The least cost (CALL_ROWS per call plus padded rows) of any multiset of buckets
    holding n rows, by trying every count of each bucket."""
    best = None
    for counts in itertools.product(*(range(-(-n // b) + 1) for b in buckets)):
        held = sum(c * b for c, b in zip(counts, buckets))
        if held >= n:
            cost = sum(c * (CALL_ROWS + b) for c, b in zip(counts, buckets))
            best = cost if best is None else min(best, cost)
    return best


@pytest.mark.parametrize("n", [1, 15, 17, 70, 200, 255, 300])
def test_one_device_covers_the_rows_at_the_least_cost(n):
    sizes = piece_sizes(n, BUCKETS)
    assert sum(sizes) >= n and all(s in BUCKETS for s in sizes)
    assert sum(CALL_ROWS + s for s in sizes) == _brute_cover_cost(n, BUCKETS)
    pieces = dealt_pieces(n, BUCKETS, 1)
    assert [size for _, size, _ in pieces] == sizes and {d for _, _, d in pieces} == {0}
    assert sum(r for r, _, _ in pieces) == n and all(0 < r <= size for r, size, _ in pieces)


@pytest.mark.parametrize("n,devices", [(2 * MIN_SHARE, 2), (300, 2), (700, 2), (1000, 3), (97, 4)])
def test_several_devices_get_near_equal_pieces_in_turn(n, devices):
    pieces = dealt_pieces(n, BUCKETS, devices)
    rows = [r for r, _, _ in pieces]
    assert sum(rows) == n and max(rows) - min(rows) <= 1  # near-equal
    assert len(pieces) % devices == 0 and len(pieces) >= len(piece_sizes(n, BUCKETS))
    assert [d for _, _, d in pieces] == [k % devices for k in range(len(pieces))]  # dealt in turn
    for r, size, _ in pieces:  # each padded to the least bucket holding it
        assert size == min(b for b in BUCKETS if b >= r)


def test_a_batch_too_small_to_share_stays_on_the_first_device():
    n = 2 * MIN_SHARE - 1
    assert dealt_pieces(n, BUCKETS, 2) == dealt_pieces(n, BUCKETS, 1)


def test_every_row_runs_once_on_its_pieces_device():
    """A call sees its piece's rows (padding repeats the piece's first row) on the device
    it was dealt; results come back in row order without the padding. The test process
    has one device: it is named twice, so the dealing is that of two."""
    device = jax.devices()[0]
    calls = DeviceCalls(BUCKETS, [device, device])
    rows = np.arange(5, 305)
    dealt = dealt_pieces(len(rows), BUCKETS, 2)
    data = np.arange(1000) * 3
    seen = []

    def call(rows_of):
        got = rows_of(data)
        seen.append((rows_of.real, rows_of.device, np.asarray(got)))
        return got + 1

    out = list(calls.run("times three", rows, call))
    assert [real for real, _, _ in seen] == [r for r, _, _ in dealt] and all(d is device for _, d, _ in seen)
    assert [len(got) for _, _, got in seen] == [size for _, size, _ in dealt]
    for (real, _, got), (piece, _) in zip(seen, out):
        assert (got[real:] == got[0]).all()  # padding: the piece's first row again
    assert np.concatenate([piece for piece, _ in out]).tolist() == rows.tolist()
    assert np.concatenate([o for _, o in out]).tolist() == (rows * 3 + 1).tolist()
    assert calls.rows_run == [sum(r for r, _, d in dealt if d == k) for k in (0, 1)] == [150, 150]
    assert {(key, d) for key, _, d in calls.compiled} == {("times three", 0), ("times three", 1)}
