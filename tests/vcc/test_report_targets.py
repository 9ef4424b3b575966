"""The report's targets table: each line judged from the files it is given, the right
file picked where several are (latest, one device, fastest), and "not run" where none is.
The files are made here; their figures are made up."""

from __future__ import annotations

import json

import pytest

from vcc import reproduce as rp
from vcc.report_targets import TARGETS, targets_section
from vccjax.errors import DataFileError

ONE, TWO = {"devices": ["cpu:0"]}, {"devices": ["cpu:0", "cpu:1"]}


def _search(date: str, run: int, seconds: float, ratio: float, machine: dict, model: str = "library",
            agree: bool = True) -> dict:
    return {"benchmark": "search", "date": date, "model": model, "budget": TARGETS["library_budget"],
            "concepts": [f"c{i}" for i in range(TARGETS["library_concepts"])], "machine": machine,
            "ratio": ratio, "results_agree": agree,
            "batched": {"programs_run": run, "seconds": seconds, "programs_per_second": 10 * run}}


def _emulator(per: dict, raster128: float) -> dict:
    return {"benchmark": "emulator", "date": "2031-01-01", "main": {"ratio": 30.0, "per_instruction": per},
            "sweeps": {"raster": [{"raster": 32, "ratio": 99.0}, {"raster": 128, "ratio": raster128}]}}


def _run(folder, settings: dict, sessions: list[float], summary: dict) -> None:
    folder.mkdir(parents=True)
    (folder / "run.json").write_text(json.dumps({"settings": settings, "sessions": sessions}))
    (folder / "summary.json").write_text(json.dumps(summary))


def _line(lines: list[str], start: str) -> str:
    got = [x for x in lines if x.startswith(start)]
    assert len(got) == 1, (start, lines)
    return got[0]


def test_emulator_lines_name_the_slowest_common_instruction_and_the_fine_raster():
    per = {"a": {"ratio": 1.0, "programs": TARGETS["instruction_programs"] - 1},  # too rare to count
           "b": {"ratio": 4.5, "programs": TARGETS["instruction_programs"]},
           "c": {"ratio": 7.0, "programs": 500}}
    common = {k: v for k, v in per.items() if v["programs"] >= TARGETS["instruction_programs"]}
    slow = min(common, key=lambda k: common[k]["ratio"])  # brute force: "b"
    lines = targets_section([("emu.json", _emulator(per, 9.5))], {})
    line = _line(lines, "| no instruction with")
    assert f"`{slow}` {per[slow]['ratio']}x" in line and line.endswith("| no |")
    assert _line(lines, f"| raster {TARGETS['raster']}").endswith("| 9.5x | no |")
    fast = {"c": {"ratio": 7.0, "programs": 500}}
    lines = targets_section([("emu.json", _emulator(fast, 12.0))], {})
    assert _line(lines, "| no instruction with").endswith("| yes |")
    assert _line(lines, f"| raster {TARGETS['raster']}").endswith("| yes |")


def test_library_search_is_judged_on_the_latest_one_device_file():
    goal = TARGETS["library_run"]
    results = [("old.json", _search("2031-01-01", goal * 4, 2.0, 25.0, ONE)),  # met, but not the latest
               ("new.json", _search("2031-02-01", goal, 2.0, 25.0, ONE)),  # the latest on one device: half the rate
               ("two.json", _search("2031-03-01", goal * 3, 2.0, 30.0, TWO)),  # later, on two devices
               ("uni.json", _search("2031-04-01", goal * 9, 2.0, 40.0, ONE, model="uniform"))]  # another benchmark
    line = _line(targets_section(results, {}), "| search on the learned library")
    assert f"| {goal // 2:,}/s, 25.0x, results agree (`new.json`, one device)" in line
    assert f"best of any setting: {goal * 2:,}/s (`old.json`), 30.0x (`two.json`) | no |" in line
    met = [("new.json", _search("2031-02-01", goal * 2, 2.0, TARGETS["library_ratio"], ONE))]
    assert _line(targets_section(met, {}), "| search on the learned library").endswith("| yes |")
    differ = [("new.json", _search("2031-02-01", goal * 2, 2.0, 25.0, ONE, agree=False))]
    line = _line(targets_section(differ, {}), "| search on the learned library")
    assert "results differ (`new.json`, one device)" in line and line.endswith("| no |")


def test_oracle_and_compile_lines_read_their_run_folders(tmp_path):
    oracle = {"order": 1, "args": "oracle", "budget": 500_000}
    others, compiled = tmp_path / "induction", tmp_path / "compile"
    _run(others / "record", oracle, [100.0, 200.0], {"concepts": 546, "found": 530, "wall_seconds": 7000})
    _run(others / "fast", oracle, [300.0], {"concepts": 546, "found": 531, "wall_seconds": 1800})
    _run(others / "sample", oracle, [50.0], {"concepts": 43, "found": 43, "wall_seconds": 60})  # not the 546
    _run(others / "predicted", {**oracle, "args": "predicted"}, [10.0],
         {"concepts": 546, "found": 500, "wall_seconds": 60})
    _run(compiled / "old", {}, [10.0], {"compile_seconds": 9.0, "wall_seconds": 11.0})
    _run(compiled / "new", {}, [20.0], {"compile_seconds": 16.5, "wall_seconds": 19.0})
    lines = targets_section([], {}, others, compiled)
    line = _line(lines, "| the 546 at 0.5M")
    assert f"(`{others / 'record'}`: 530) | 531 in 30 min (`{others / 'fast'}`) | yes |" in line
    assert _line(lines, "| compile time").endswith(f"| 16.5 s of a 19.0 s run (`{compiled / 'new'}`) | no |")


def test_rows_lines_and_nothing_measured():
    lines = targets_section([], {}, None, None)
    for start in ("| JAX emulator", "| search >=", "| the 546 at 0.5M", "| compile time", "| all 546",
                  f"| the {TARGETS['long_row']} row"):
        assert _line(lines, start).endswith("| not run | - |")
    assert _line(lines, "| every row").endswith(f"| 0 of {len(rp.ROWS)} | no |")
    main = {"complete": True, "found": TARGETS["main_found"], "exact_on_all_test_pairs": TARGETS["main_exact"],
            "wall_seconds": TARGETS["main_wall_s"]}
    long = {"complete": False, "found": TARGETS["long_found"]}  # enough found, but cut short
    rows = {rp.MAIN: main, TARGETS["long_row"]: long}
    lines = targets_section([], rows)
    assert _line(lines, "| all 546").endswith("| yes |")
    assert _line(lines, f"| the {TARGETS['long_row']} row").endswith(f"| {TARGETS['long_found']} (partial) | no |")
    slow = targets_section([], {rp.MAIN: {**main, "wall_seconds": TARGETS["main_wall_s"] + 1}})
    assert _line(slow, "| all 546").endswith("| no |")
    every = {r.name: {"complete": True, "found": 1, "exact_on_all_test_pairs": 1, "wall_seconds": 1}
             for r in rp.ROWS}
    assert _line(targets_section([], every), "| every row").endswith(f"| {len(rp.ROWS)} of {len(rp.ROWS)} | yes |")


def test_a_file_or_a_corrupt_run_is_named_in_one_error(tmp_path):
    afile = tmp_path / "a.txt"
    afile.write_text("x")
    with pytest.raises(DataFileError, match=f"^{afile}: not a folder of run folders$"):
        targets_section([], {}, None, afile)
    bad = tmp_path / "compile" / "x"
    bad.mkdir(parents=True)
    (bad / "run.json").write_text("{")
    (bad / "summary.json").write_text("{}")
    with pytest.raises(DataFileError, match=f"^{bad / 'run.json'}: not JSON"):
        targets_section([], {}, None, tmp_path / "compile")
    (bad / "run.json").write_text("[]")
    with pytest.raises(DataFileError, match="must hold objects"):
        targets_section([], {}, tmp_path / "compile", None)
