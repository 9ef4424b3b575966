"""Explore-compress on a local Ray cluster of two single-CPU workers: the same
`results.jsonl` as one process, also when a worker is killed mid-run."""

from __future__ import annotations

import json
import os
import signal
import threading
import time

import pytest

pytest.importorskip("ray")

pytestmark = [pytest.mark.xdist_group("ray"),  # one cluster at a time on a small machine
              pytest.mark.filterwarnings("ignore:os.fork")]  # Ray starts its processes by fork and exec

CONCEPTS = 6  # of the demo set: three chunks of two for two workers
SETTINGS = {"budget": 20_000, "args": "oracle", "max_iterations": 2}


def _rows(out) -> list[tuple]:
    with open(out / "results.jsonl") as f:
        records = [json.loads(line) for line in f]
    return [(r["concept"], r["program"], r["iteration"]) for r in records]


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    """The concepts, their examples and the single-process run to compare with."""
    from search.explore import Explorer
    from search.induce import Settings, induce
    from vccjax import runtime
    from vccjax.world.concepts import concept_list
    from vccjax.world.dataset import dataset_for

    runtime.prepare()
    names = list(concept_list("demo"))[:CONCEPTS]
    ds = dataset_for(names, 0, None, progress=False)

    def run(out, searcher):
        induce(names, ds.pairs, out, Settings(**SETTINGS), explorer=searcher, progress=False,
               log=lambda _: None, examples_sha256=ds.sha256, answers=ds.program)
        return _rows(out)

    single = run(tmp_path_factory.mktemp("single"), Explorer(width=2))
    assert len(single) >= CONCEPTS  # every concept has a row
    return run, single


def test_two_workers_give_the_single_process_results(setup, tmp_path):
    from search.cluster import ClusterSearcher

    run, single = setup
    with ClusterSearcher(workers=2, width=2) as searcher:
        got = run(tmp_path, searcher)
        assert searcher.retried == 0
    assert sorted(got) == sorted(single)
    assert len(got) == len(set(got))


def test_a_worker_killed_mid_run_loses_and_repeats_nothing(setup, tmp_path):
    """The worker holding a chunk is killed (SIGKILL) while it runs it: the chunk runs
    again on a worker started in its place; every concept is written once, with the
    result the single process found."""
    from search.cluster import ClusterSearcher

    run, single = setup
    with ClusterSearcher(workers=2, width=2) as searcher:
        pids = searcher.worker_pids()
        killed: list[int] = []

        def kill_a_busy_worker():
            deadline = time.monotonic() + 300
            while not searcher.in_flight and time.monotonic() < deadline:
                time.sleep(0.01)
            slot = next(iter(searcher.in_flight), None)
            if slot is not None:
                os.kill(pids[slot], signal.SIGKILL)
                killed.append(slot)

        killer = threading.Thread(target=kill_a_busy_worker)
        killer.start()
        got = run(tmp_path, searcher)
        killer.join()
        assert killed, "no chunk was ever in flight"
        assert searcher.retried >= 1
    assert sorted(got) == sorted(single)
    assert len(got) == len(set(got))


def test_vcc_induce_on_a_local_cluster_writes_one_row_per_concept(tmp_path):
    """The command line: `--cluster ray --workers 1` starts a local cluster, runs, stops it."""
    import subprocess
    import sys

    out = tmp_path / "run"
    names = "remove_top_obj,remove_bottom_obj"
    done = subprocess.run([sys.executable, "-m", "vcc", "induce", "--concepts", names, "--budget", "2000",
                           "--args", "oracle", "--iterations", "1", "--width", "1", "--cluster", "ray",
                           "--workers", "1", "--quiet", "--out", str(out)], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert sorted(c for c, _, _ in _rows(out)) == sorted(names.split(","))


def test_vcc_bench_reproduce_on_a_local_cluster_gives_the_single_process_rows(tmp_path):
    """A paper's row on workers (`vcc bench reproduce --cluster ray`): the rows one process
    writes, concept for concept."""
    import subprocess
    import sys

    def reproduce(where, *more):
        done = subprocess.run([sys.executable, "-m", "vcc", "bench", "reproduce", "--rows", "examples-2",
                               "--concepts", "remove_top_obj,remove_bottom_obj", "--scale", "0.004", "--width", "1",
                               "--quiet", "--runs", str(where / "runs"), "--out", str(where / "r.json"),
                               "--report", str(where / "REPORT.md"), "--others", "", "--robot", "", *more],
                              capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr[-2000:]
        (row,) = (where / "runs").iterdir()
        return sorted(_rows(row))

    single = reproduce(tmp_path / "one")
    assert [c for c, _, _ in single] == ["remove_bottom_obj", "remove_top_obj"]
    assert reproduce(tmp_path / "ray", "--cluster", "ray", "--workers", "1") == single


def test_a_chunk_that_keeps_killing_its_worker_ends_the_run_with_its_name():
    """A lost host is retried; a chunk whose worker dies every time is a bug: after
    MAX_TRIES reruns the pool stops with a line naming the chunk, the other chunks done."""
    from vccjax.actor_pool import MAX_TRIES, ActorPool

    class Echo:  # defined here: Ray ships it to the workers by value
        def pid(self) -> int:
            return os.getpid()

        def twice(self, x: int) -> int:
            if x < 0:
                os._exit(1)  # the worker process dies under this chunk
            return 2 * x

    got = {}
    with ActorPool(Echo, lambda slot: (), workers=2) as pool:
        pool.map("twice", [(1,), (2,), (3,)], got.__setitem__)
        assert got == {0: 2, 1: 4, 2: 6} and pool.retried == 0
        with pytest.raises(RuntimeError, match=f"chunk 1 of 3 killed its worker {MAX_TRIES + 1} times"):
            pool.map("twice", [(5,), (-1,), (7,)], got.__setitem__)
        assert pool.retried == MAX_TRIES
