"""Map a function over jobs in worker processes, with a progress bar: the pattern that
dataset builds and end-to-end measurements share."""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence


def map_with_progress(fn: Callable, jobs: Sequence, workers: int, chunksize: int, desc: str,
                      progress: bool, unit: str = "it") -> list:
    """`[fn(job) for job in jobs]`, in `workers` spawned processes when more than one
    (spawn, not fork: the parent may have started JAX's threads)."""
    from tqdm import tqdm

    results = []
    with tqdm(total=len(jobs), desc=desc, unit=unit, disable=not progress) as bar:
        if workers > 1:
            pool = multiprocessing.get_context("spawn").Pool(workers, initializer=_leave_ctrl_c_to_the_parent)
            try:
                for r in pool.imap(fn, jobs, chunksize=chunksize):
                    results.append(r)
                    bar.update()
                pool.close()
            except BaseException:  # Ctrl-C (or a job's error): the workers stop now, not after their jobs
                pool.terminate()
                raise
            finally:
                pool.join()
        else:
            for job in jobs:
                results.append(fn(job))
                bar.update()
    return results


def _leave_ctrl_c_to_the_parent() -> None:
    """A worker ignores Ctrl-C (the terminal sends it to the whole group): the parent
    takes it, stops the workers and says so in one line."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
