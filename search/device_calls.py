"""Device calls over rows of host arrays: padded to a few batch sizes, dealt out to the
devices, started without waiting, compile time kept apart.

A search steps batches of every size; XLA compiles a function once per input shape, so
each batch is cut into pieces of a few fixed sizes (buckets) and each piece padded to
its size by repeating a row. With several devices the pieces are dealt out whole, one
device each in turn, and a batch too small to give every device a piece is cut into one
near-equal piece per device: each device runs its own pieces while the others run
theirs (on a CPU host, `XLA_FLAGS=--xla_force_host_platform_device_count=N` makes N
devices). Pieces are dispatched without waiting for the results, so the host prepares
the next while the devices run.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable, Hashable, Iterable, Iterator, Sequence

import jax
import numpy as np

CALL_ROWS = 8  # a device call's fixed cost, in rows stepped
BUCKETS = (16, 64, 256, 1024, 4096)  # the search's padded batch sizes

MIN_SHARE = 16  # rows a device must get before a small batch is cut into one piece per device
RowsOf = Callable[..., object]  # `rows_of(a)` / `rows_of(a, via)`: a host array's rows for one piece
Pending = list[tuple[np.ndarray, object]]  # (rows of each piece, its device outputs with the padding)


@functools.lru_cache(maxsize=8192)
def _cheapest_cover(n: int, buckets: tuple[int, ...]) -> tuple[int, ...]:
    """The cheapest multiset of buckets holding n rows (n < the largest bucket)."""
    best: list = [(0, ())] + [None] * n  # rows -> (cost, pieces)
    for m in range(1, n + 1):
        best[m] = min((CALL_ROWS + b + best[max(m - b, 0)][0], (b,) + best[max(m - b, 0)][1]) for b in buckets)
    return best[n][1]


def piece_sizes(n: int, buckets: Sequence[int]) -> list[int]:
    """Bucket sizes covering n rows at the least cost, counting each call as CALL_ROWS
    rows of fixed overhead plus its padded rows (one 1024 call for 300 rows wastes more
    than a 256 and a 64 cost)."""
    buckets = tuple(sorted(buckets))
    full, rest = divmod(n, buckets[-1])
    return [buckets[-1]] * full + (list(_cheapest_cover(rest, buckets)) if rest else [])


def dealt_pieces(n: int, buckets: Sequence[int], devices: int) -> list[tuple[int, int, int]]:
    """(rows, padded size, device index) of the pieces covering n rows in order: one
    device's `piece_sizes`; over several devices, at least one piece per device when each
    gets `MIN_SHARE` rows or more, the pieces near-equal (a multiple of the device count
    of them, each padded to the least bucket that holds it), dealt out in turn."""
    buckets = tuple(sorted(buckets))
    sizes = piece_sizes(n, buckets)
    if devices == 1 or n < devices * MIN_SHARE:  # the last piece holds what the others leave
        return [(size, size, 0) for size in sizes[:-1]] + [(n - sum(sizes[:-1]), sizes[-1], 0)]
    k = -(-max(len(sizes), devices) // devices) * devices
    rows = [n // k + (i < n % k) for i in range(k)]
    return [(r, next(b for b in buckets if b >= r), i % devices) for i, r in enumerate(rows)]


class DeviceCalls:
    """Runs calls over rows in bucket-sized pieces on `devices` (default: all JAX devices),
    counting the first call of each (key, size, device) as compile time."""

    def __init__(self, buckets: Sequence[int], devices: Sequence[jax.Device] | None = None):
        self.devices = list(devices) if devices is not None else jax.devices()
        self.buckets = tuple(sorted(buckets))
        self.compiled: set[tuple] = set()  # (key, size, device) seen
        self.compile_seconds = 0.0  # first calls of each (key, size, device): compile time, kept apart
        self.rows_run = [0] * len(self.devices)  # rows (padding not counted) each device was given

    def start(self, key: Hashable, rows: np.ndarray, call: Callable[[RowsOf], object],
              sizes: Sequence[int] | None = None) -> Pending:
        """Start `call(rows_of)` over `rows` in bucket-sized pieces (`sizes`, default this
        caller's buckets; each padded by repeating its first row), dealt out to the devices
        (`dealt_pieces`), without waiting for the results. `rows_of(a)` gives a host array's
        rows of the piece on its device, `rows_of.real` its rows before the padding,
        `rows_of.device` the device (what else the call reads must be there). First calls
        of a (key, size, device) compile synchronously and are timed as compile time.
        Returns the pending pieces, for `results`."""
        offset, pending = 0, []
        for real, size, d in dealt_pieces(len(rows), sizes or self.buckets, len(self.devices)):
            piece = rows[offset : offset + real]
            padded = np.concatenate([piece, np.full(size - len(piece), piece[0])])
            first = (key, size, d) not in self.compiled
            t0 = time.perf_counter()
            rows_of = self.rows_on_device(padded, d, real)
            pending.append((piece, call(rows_of)))
            if first:
                jax.block_until_ready(pending[-1][1])
                self.compiled.add((key, size, d))
                self.compile_seconds += time.perf_counter() - t0
            self.rows_run[d] += real
            offset += real
        return pending

    @staticmethod
    def results(pending: Pending) -> Iterator[tuple[np.ndarray, object]]:
        """(rows, host outputs without the padding) of started pieces, waiting for each."""
        for piece, out in pending:
            yield piece, jax.tree.map(lambda a: np.asarray(a)[: len(piece)], out)  # noqa: B023

    def run(self, key: Hashable, rows: np.ndarray, call: Callable[[RowsOf], object],
            sizes: Sequence[int] | None = None) -> Iterable:
        """`start` and `results` at once."""
        return self.results(self.start(key, rows, call, sizes))

    def rows_on_device(self, padded: np.ndarray, d: int, real: int) -> RowsOf:
        """What `call` gets for a piece on device `d` whose first `real` rows are its own:
        `rows_of(a)`, the padded rows of a host array (`rows_of(a, via)`: rows `via[padded]`
        of it), put on that device (with one device, handed over as they are: the jitted
        call moves them)."""
        device = self.devices[d]

        def rows_of(a: np.ndarray, via: np.ndarray | None = None):
            rows = a[padded if via is None else via[padded]]
            return rows if len(self.devices) == 1 else jax.device_put(rows, device)
        rows_of.real = real
        rows_of.device = device
        return rows_of

    def piece_sizes(self, n: int) -> list[int]:
        """`piece_sizes` over this caller's buckets."""
        return piece_sizes(n, self.buckets)
