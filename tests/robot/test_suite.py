"""The arm's suite and stress runs: where programs come from (a `vcc induce` run, the
user's library, the reference), one record per scenario, resume, shards; no MJX runs."""

from __future__ import annotations

import pytest

import robot  # noqa: F401  (sets MUJOCO_GL before mujoco is imported)
from vccjax.world.concepts import reference_program


def test_stress_batches_are_drawn_the_same_each_time():
    """A resumed `vcc robot stress` redraws a batch from (seed, batch) alone, from the
    learned programs of the run of record."""
    from robot.choice import arm_able
    from robot.sources import RUN_OF_RECORD, Programs
    from robot.stress import draw_batch

    learned = Programs(str(RUN_OF_RECORD))
    a, b, c = (draw_batch(7, k, learned, size=4) for k in (3, 3, 4))
    assert [(n, s.seed, s.slots) for n, _, s in a] == [(n, s.seed, s.slots) for n, _, s in b]
    assert [s.seed for _, _, s in a] != [s.seed for _, _, s in c]
    assert all(n in arm_able(learned.table) and p == learned.table[n] for n, p, _ in a)


def test_suite_writes_one_record_per_scenario_and_resumes_without_redoing(tmp_path, monkeypatch):
    """`vcc robot suite`: one file per concept with a record per scenario and the program's
    source and hash; a finished concept is kept, and one made with another program,
    source or seed is redone."""
    import json

    import robot.rollout
    from robot.judge import Verdict
    from robot.sources import Programs
    from robot.suite import run_suite

    calls = []

    class FakeBench:
        def run_pairs(self, items, keep=False, pad_to=None):
            assert pad_to == 32  # every batch one size: one MJX compilation
            calls.append(len(items))
            vs = [Verdict(k % 2 == 0, None if k % 2 == 0 else "object dropped", "", 0.0, s.seed)
                  for k, (_, s) in enumerate(items)]
            return vs, {"compile_s": 0.0, "rollout_s": 0.0}, []

    monkeypatch.setattr(robot.rollout, "Bench", FakeBench)
    run = tmp_path / "run"
    run.mkdir()
    found = ("scene_parse; fixate(bottom); top_down_attend; move_hand_to_attended_object; grab_object; "
             "move_hand_to_pointer")
    lines = [{"concept": "move_bottom_to_pointed", "found": True, "program": found},
             {"concept": "move_green_to_right_bottom_corner", "found": True,
              "program": reference_program("move_green_to_right_bottom_corner").text()}]
    (run / "results.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))
    learned = Programs(str(run))
    two = ("move_bottom_to_pointed", "move_green_to_right_bottom_corner")
    out = tmp_path / "out"
    s = run_suite(out, learned, two[:1], scenarios=4, log=lambda _: None)
    assert calls == [4] and s["success"] == 2 and s["failures"] == {"object dropped": 2}
    s = run_suite(out, learned, two, scenarios=4, log=lambda _: None)
    assert calls == [4, 4] and s["concepts"] == 2 and s["rollouts"] == 8  # the first was not redone
    record = json.loads((out / "move_bottom_to_pointed.json").read_text())
    assert record["programs"] == [found] and record["source"]["kind"] == "run"
    assert record["source"]["path"] == str(run.resolve()) and len(record["source"]["sha256"]) == 64
    assert [r["seed"] for r in record["records"]] == [0, 1, 2, 3] and record["success"] == 2
    assert not list(out.glob("*.tmp"))
    run_suite(out, learned, two[:1], scenarios=4, seed=1, log=lambda _: None)
    assert calls == [4, 4, 4]  # another seed is another run: redone, not kept
    run_suite(out, Programs("reference"), two[:1], scenarios=4, seed=1, log=lambda _: None)
    assert calls == [4, 4, 4, 4]  # another source (the reference program) too
    # two concepts share one batch; a shard runs only its share
    calls.clear()
    fresh = tmp_path / "fresh"
    run_suite(fresh, learned, two, scenarios=4, shard=(1, 2), log=lambda _: None)
    assert calls == [4] and [p.name for p in fresh.glob("move_*.json")] == ["move_green_to_right_bottom_corner.json"]
    run_suite(fresh, learned, two, scenarios=4, log=lambda _: None)
    assert calls == [4, 4]
    calls.clear()
    run_suite(tmp_path / "both", learned, two, scenarios=4, log=lambda _: None)
    assert calls == [8]


def test_suite_status_summarises_a_folder_without_running(tmp_path, capsys):
    import json

    from vcc.cli import main

    assert main(["robot", "suite", "--out", str(tmp_path), "--concepts", "move_all_yellow_left", "--status"]) == 0
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["concepts"] == 0 and s["of"] == 1 and s["source"]["path"] == "benchmarks/induction/o1-oracle-500k"
    assert "0 of 1 concepts recorded" in capsys.readouterr().out


def test_programs_come_from_an_induce_run_when_asked(tmp_path):
    import json

    from robot.sources import programs_of
    from vccjax.errors import DataFileError

    found = ("scene_parse; fixate(bottom); top_down_attend; move_hand_to_attended_object; grab_object; "
             "move_hand_to_pointer")  # no release: the arm puts the object down at the end
    lines = [{"concept": "move_bottom_to_pointed", "found": False, "program": None},
             {"concept": "move_bottom_to_pointed", "found": True, "program": found}]
    (tmp_path / "results.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))
    assert programs_of("move_bottom_to_pointed", tmp_path).text() == found
    assert programs_of("move_bottom_to_pointed") == reference_program("move_bottom_to_pointed")
    with pytest.raises(ValueError, match="move_to_middle: not induced in"):
        programs_of("move_bottom_to_pointed+move_to_middle", tmp_path)
    with pytest.raises(DataFileError, match="results.jsonl: missing"):
        programs_of("move_bottom_to_pointed", tmp_path / "none")
    (tmp_path / "results.jsonl").write_text("{not json\n" + json.dumps(lines[1]) + "\n")  # not a last line cut short
    with pytest.raises(DataFileError, match="line 1 is not a JSON record"):
        programs_of("move_bottom_to_pointed", tmp_path)


def test_a_concept_saved_by_vcc_learn_is_carried_out_by_name(tmp_path, monkeypatch, capsys):
    from robot.sources import Programs, programs_of
    from vcc.cli import main
    from vccjax.machine.program import parse
    from vccjax.world.user_concepts import save_concept

    monkeypatch.setenv("VCC_LIBRARY", str(tmp_path))
    learned = "scene_parse; fixate(right); top_down_attend; move_hand_to_attended_object; grab_object; move_hand_up"
    save_concept("lift_right_most", {"program": learned, "pairs": 3})
    assert programs_of("lift_right_most") == parse(learned)
    assert programs_of("lift_right_most+move_to_middle")[1] == reference_program("move_to_middle")
    library = Programs("library")  # the suite's --source library
    assert library.of("lift_right_most") == parse(learned) and library.source.kind == "library"
    with pytest.raises(ValueError, match="move_to_middle: not in the user's library"):
        library.of("lift_right_most+move_to_middle")
    save_concept("paint_it", {"program": "scene_parse; top_down_attend; fill_color(red)"})
    assert main(["robot", "run", "--concept", "paint_it", "--scenarios", "1"]) == 2  # refused before MJX starts
    assert "recolours an object" in capsys.readouterr().err
    assert main(["robot", "run", "--concept", "no_such_saved"]) == 2
    assert "not in your library" in capsys.readouterr().err


def test_stress_resumes_from_its_batch_records_without_redoing_them(tmp_path, monkeypatch):
    """`vcc robot stress` stopped after some batches: run again, it keeps the finished
    batches (redrawing nothing) and runs only the rest; a batch of another seed is redone.
    A scenario not run (no placement error measured) is recorded, not a crash."""
    import json

    import robot.rollout
    from robot.judge import Verdict
    from robot.sources import Programs
    from robot.stress import BATCH, run_stress

    calls = []

    class FakeBench:
        def run_pairs(self, items, keep=False, pad_to=None):
            calls.append(len(items))  # the first scenario not run (its error not measured: nan)
            vs = [Verdict(k > 0, None if k else "no scenario", "", 0.0 if k else float("nan"), s.seed)
                  for k, (_, s) in enumerate(items)]
            return vs, {"compile_s": 0.0, "rollout_s": 0.0}, [None] * len(items)

    monkeypatch.setattr(robot.rollout, "Bench", FakeBench)
    reference = Programs("reference")
    s = run_stress(tmp_path, reference, rollouts=BATCH, seed=3, log=lambda _: None)
    assert calls == [BATCH] and s["success"] == BATCH - 1 and s["batches"] == 1
    s = run_stress(tmp_path, reference, rollouts=2 * BATCH, seed=3, log=lambda _: None)
    assert calls == [BATCH, BATCH] and s["success"] == 2 * (BATCH - 1)  # batch 0 kept, batch 1 run
    assert s["failures"] == {"no scenario": 2}
    kept = json.loads((tmp_path / "batch-000.json").read_text())  # strict JSON: the nan is null
    assert kept["seed"] == 3 and len(kept["concepts"]) == BATCH and kept["verdicts"][0]["max_error_m"] is None
    run_stress(tmp_path, reference, rollouts=BATCH, seed=4, log=lambda _: None)
    assert calls == [BATCH, BATCH, BATCH]  # another seed: redone


def test_a_suite_on_a_worker_pool_writes_what_one_process_writes(tmp_path, monkeypatch):
    """`vcc robot suite --cluster ray`: the batches go to the pool's workers and come back
    in any order; this process writes the same records as a run on its own (a fake pool
    here; the pool itself is tested with Ray in tests/search/test_cluster.py)."""
    import json

    import robot.rollout
    from robot.judge import Verdict
    from robot.sources import Programs
    from robot.suite import run_suite

    def verdicts(pairs):  # scenario by scenario, as a rollout would: the same wherever it runs
        return [Verdict(s.seed % 3 != 1, None if s.seed % 3 != 1 else "misplaced", "", 0.0, s.seed) for _, s in pairs]

    class FakeBench:
        def run_pairs(self, items, keep=False, pad_to=None):
            return verdicts(items), {"compile_s": 0.0, "rollout_s": 0.0}, []

    class FakePool:
        def __init__(self):
            self.batches = []

        def map(self, method, chunks, done):
            assert method == "roll"
            for i in reversed(range(len(chunks))):  # the last batch back first
                (pairs,) = chunks[i]
                self.batches.append(len(pairs))
                done(i, (verdicts(pairs), {"compile_s": 0.0, "rollout_s": 0.0, "wall_s": 0.0}))

    monkeypatch.setattr(robot.rollout, "Bench", FakeBench)
    names = ["move_green_to_right_bottom_corner", "move_all_yellow_left", "move_bottom_to_pointed"]
    pool = FakePool()
    alone = run_suite(tmp_path / "alone", Programs("reference"), names, scenarios=16, log=lambda _: None)
    spread = run_suite(tmp_path / "pool", Programs("reference"), names, scenarios=16, log=lambda _: None, pool=pool)
    assert pool.batches == [16, 32]  # whole concepts, at most 32 scenarios a batch
    assert spread["success"] == alone["success"] and spread["failures"] == alone["failures"]
    assert spread["rollouts"] == alone["rollouts"] == 48
    for name in names:
        a, b = (json.loads((tmp_path / d / f"{name}.json").read_text()) for d in ("alone", "pool"))
        assert a["records"] == b["records"] and a["programs"] == b["programs"]
