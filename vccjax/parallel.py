"""Map a function over jobs in worker processes, with a progress bar: the pattern that
dataset builds and end-to-end measurements share."""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor


def map_with_progress(fn: Callable, jobs: Sequence, workers: int, chunksize: int, desc: str,
                      progress: bool, unit: str = "it") -> list:
    """`[fn(job) for job in jobs]`, in `workers` spawned processes when more than one
    (spawn, not fork: the parent may have started JAX's threads)."""
    from tqdm import tqdm

    results = []
    with tqdm(total=len(jobs), desc=desc, unit=unit, disable=not progress) as bar:
        if workers > 1:
            with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
                for r in pool.map(fn, jobs, chunksize=chunksize):
                    results.append(r)
                    bar.update()
        else:
            for job in jobs:
                results.append(fn(job))
                bar.update()
    return results
