"""`vcc bench`: runs on a tiny setting, and writes a stamped result whose two
implementations agree (speed itself is measured, never asserted)."""

from __future__ import annotations

import json

from vcc.cli import main


def test_bench_search_compares_batched_and_scalar_on_the_same_concepts(tmp_path, capsys):
    out = tmp_path / "search.json"
    argv = ["bench", "search", "--concepts", "remove_bottom_obj,change_all_objs_color", "--budget", "2000",
            "--width", "2", "--out", str(out)]  # examples: the dataset shipped in the package
    assert main(argv) == 0
    text = capsys.readouterr().out
    r = json.loads(out.read_text())
    assert r["results_agree"] is True and r["found"] >= 1
    assert r["batched"]["programs_searched"] == r["scalar"]["programs_searched"] > 0
    assert r["batched"]["nodes"] == r["scalar"]["nodes"]
    assert r["ratio"] > 0 and f"{r['ratio']}x" in text
    assert {"date", "commit", "machine", "command"} <= set(r) and r["machine"]["cores"] >= 1


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
    from vccjax.dataset import dataset_for
    from vccjax.instructions import OP

    ds = dataset_for(["remove_bottom_obj"], 0, None, progress=False)
    chain = Chain(Vocabulary(), MarkovModel.uniform(Vocabulary().size, 1),
                  argument_logp(Settings(args="oracle"), "remove_bottom_obj"))
    stream = record_stream([(chain, Task.from_pairs(ds.pairs("remove_bottom_obj", "train")))], 50)
    assert len(stream) == 50 and stream[0][1].ops == () and stream[0][2] == OP["scene_parse"]
    assert all(len(p) == 0 or p.ops[0] == OP["scene_parse"] for _, p, _, _ in stream)
