"""`vcc bench emulator`: a recorded search stream stepped on both machines, in the
search's order and batches, agreeing (speed itself measured, never asserted)."""

from __future__ import annotations

import json

from vcc.cli import main


def test_bench_emulator_steps_a_recorded_search_stream_on_both_machines(tmp_path, capsys):
    out = tmp_path / "emulator.json"
    argv = ["bench", "emulator", "--concepts", "remove_bottom_obj,move_to_middle", "--per-concept", "30",
            "--batch", "32", "--objects", "3", "--raster", "", "--repeats", "1", "--out", str(out)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    r = json.loads(out.read_text())
    assert r["stream"]["programs"] == 60 and sum(r["stream"]["instructions"].values()) == 60
    m = r["main"]
    assert m["agree"] is True and m["programs"] == 60 and m["examples"] == 10
    assert m["jax_programs_per_second"] > 0 and m["reference_programs_per_second"] > 0
    assert sum(v["programs"] for v in m["per_instruction"].values()) == 60
    assert [x["objects"] for x in r["sweeps"]["objects"]] == [3] and r["sweeps"]["objects"][0]["agree"] is True
    assert f"mixed stream: {m['ratio']}x" in text and {"date", "commit", "machine", "command"} <= set(r)


def test_the_recorded_stream_is_what_the_search_steps_first():
    """Children in the search's order: the first are scene_parse's, then its children."""
    from search.chain import Chain
    from search.explore import Task
    from search.induce import Settings, argument_logp
    from search.model import MarkovModel, Vocabulary
    from vcc.emulator_bench import record_stream
    from vccjax.world.dataset import dataset_for
    from vccjax.machine.instructions import OP

    ds = dataset_for(["remove_bottom_obj"], 0, None, progress=False)
    chain = Chain(Vocabulary(), MarkovModel.uniform(Vocabulary().size, 1),
                  argument_logp(Settings(args="oracle"), "remove_bottom_obj"))
    stream = record_stream([(chain, Task.from_pairs(ds.pairs("remove_bottom_obj", "train")))], 50)
    assert len(stream) == 50 and stream[0][1].ops == () and stream[0][2] == OP["scene_parse"]
    assert all(len(p) == 0 or p.ops[0] == OP["scene_parse"] for _, p, _, _ in stream)


def test_bench_emulator_cuts_batches_as_the_search_does():
    """Each instruction's children go in the search's padded sizes (its cheapest cover,
    capped at the bench's batch), every child once; a carry op's holding rows apart when
    that makes the carrying calls smaller, as the search splits them."""
    import numpy as np

    from search.device_calls import BUCKETS, DeviceCalls
    from search.stepping import EMPTY_HANDED
    from vcc.emulator_bench import _parts, _pieces

    for n, batch in [(1, 1024), (17, 1024), (300, 1024), (658, 1024), (2500, 1024), (70, 64)]:
        pieces = _pieces(n, batch)
        calls = DeviceCalls([b for b in BUCKETS if b < batch] + [batch])
        assert [len(p) for p in pieces] == calls.piece_sizes(n)
        assert sorted(set(np.concatenate(pieces).tolist())) == list(range(n))
        assert all(len(p) <= batch and set(p.tolist()) <= set(range(n)) for p in pieces)

    def group_of(held):
        class Hand:
            pass

        class States:
            hand = Hand

        Hand.held = np.asarray(held)
        return {"rows": np.arange(len(held)), "states": States}

    carry = next(iter(EMPTY_HANDED))
    # 4 rows, rows 1 and 3 holding on some example: both halves pad to one 16-row call,
    # as the whole does, so splitting would only add a call.
    small = group_of([[-1, -1], [-1, 2], [-1, -1], [0, 0]])
    assert [p.tolist() for p in _parts(carry, small, 1024)] == [[0, 1, 2, 3]]
    # 40 rows (three 16-row calls), 10 holding (one 16-row call): the carry runs on 16
    # padded rows instead of 48, so the holding rows go apart.
    held = [[-1, 0] if r % 4 == 0 else [-1, -1] for r in range(40)]
    big = group_of(held)
    assert [p.tolist() for p in _parts(carry, big, 1024)] == [list(range(0, 40, 4)),
                                                             [r for r in range(40) if r % 4]]
    assert [p.tolist() for p in _parts(-1, big, 1024)] == [list(range(40))]
