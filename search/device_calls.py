"""Device calls over rows of host arrays: padded to a few batch sizes, split over the
devices, started without waiting, compile time kept apart.

A search steps batches of every size; XLA compiles a function once per input shape, so
each batch is cut into pieces of a few fixed sizes (buckets) and each piece padded to
its size by repeating a row. Each piece is split by rows over the JAX devices (a
one-axis mesh: each device runs its share). Pieces are dispatched without waiting for
the results, so the host prepares the next while the device runs one.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable, Hashable, Iterable, Iterator, Sequence

import jax
import numpy as np
from jax.sharding import Mesh, NamedSharding
from jax.sharding import PartitionSpec as P

CALL_ROWS = 8  # a device call's fixed cost, in rows stepped
BUCKETS = (16, 64, 256, 1024, 4096)  # the search's padded batch sizes

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


class DeviceCalls:
    """Runs calls over rows in bucket-sized pieces on `devices` (default: all JAX devices),
    counting the first call of each (key, size) as compile time."""

    def __init__(self, buckets: Sequence[int], devices: Sequence[jax.Device] | None = None):
        self.devices = list(devices) if devices is not None else jax.devices()
        if any(b % len(self.devices) for b in buckets):
            raise ValueError(f"batch sizes {tuple(buckets)} must divide over {len(self.devices)} devices")
        mesh = Mesh(np.array(self.devices), ("rows",))
        self.split_by_rows = NamedSharding(mesh, P("rows"))  # each device a share of the rows
        self.everywhere = NamedSharding(mesh, P())  # a copy on each device
        self.buckets = tuple(sorted(buckets))
        self.compiled: set[tuple] = set()  # (key, size) seen
        self.compile_seconds = 0.0  # first calls of each (key, size): compile time, kept apart

    def start(self, key: Hashable, rows: np.ndarray, call: Callable[[RowsOf], object],
              sizes: Sequence[int] | None = None) -> Pending:
        """Start `call(rows_of)` over `rows` in bucket-sized pieces (`sizes`, default this
        caller's buckets; each padded by repeating its first row; `rows_of(a)` gives a host
        array's rows of the piece, `rows_of.real` its rows before the padding) without
        waiting for the results. First calls of a (key, size) compile synchronously and are timed
        as compile time. Returns the pending pieces, for `results`."""
        offset, pending = 0, []
        for size in piece_sizes(len(rows), sizes) if sizes else self.piece_sizes(len(rows)):
            piece = rows[offset : offset + size]
            padded = np.concatenate([piece, np.full(size - len(piece), piece[0])])
            first = (key, size) not in self.compiled
            t0 = time.perf_counter()
            rows_of = self.rows_on_devices(padded)
            rows_of.real = len(piece)  # the piece's rows before the padding
            pending.append((piece, call(rows_of)))
            if first:
                jax.block_until_ready(pending[-1][1])
                self.compiled.add((key, size))
                self.compile_seconds += time.perf_counter() - t0
            offset += size
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

    def rows_on_devices(self, padded: np.ndarray) -> RowsOf:
        """What `call` gets: `rows_of(a)`, the padded rows of a host array (`rows_of(a, via)`:
        rows `via[padded]` of it), split over the devices by rows when there are several
        (XLA then runs each device's share)."""
        def rows_of(a: np.ndarray, via: np.ndarray | None = None):
            rows = a[padded if via is None else via[padded]]
            return rows if len(self.devices) == 1 else jax.device_put(rows, self.split_by_rows)
        return rows_of

    def piece_sizes(self, n: int) -> list[int]:
        """`piece_sizes` over this caller's buckets."""
        return piece_sizes(n, self.buckets)
