"""`vcc bench reproduce`: rows run on a tiny budget, resumed, kept when finished under
settings since changed, and a row's last pass searched anew."""

from __future__ import annotations

import json

from vcc.cli import main


def _reproduce(tmp_path, *more):
    return ["bench", "reproduce", "--concepts", "remove_bottom_obj,swap_locations", "--scale", "0.002",
            "--width", "2", "--quiet", "--runs", str(tmp_path / "runs"), "--out", str(tmp_path / "res" / "r.json"),
            "--report", str(tmp_path / "REPORT.md"), *more]


def test_bench_reproduce_runs_rows_resumes_and_reports_the_rest_as_not_run(tmp_path, capsys):
    assert main(_reproduce(tmp_path, "--rows", "o1-predfix-0.5M,examples-2")) == 0
    from vcc.reproduce import concept_tag

    runs, tag = tmp_path / "runs", concept_tag("list", ["swap_locations", "remove_bottom_obj"])
    assert tag.startswith("2concepts-") and tag != concept_tag("list", ["swap_locations", "remove_top_obj"])
    main_row, curve = runs / f"o1-predfix-0.5M-{tag}-x0.002", runs / f"examples-2-{tag}-x0.002"
    s = json.loads((main_row / "summary.json").read_text())
    assert s["complete"] and s["concepts"] == 2 and s["found"] >= 1
    assert json.loads((main_row / "run.json").read_text())["settings"]["budget"] == 1000  # 0.5M x 0.002
    # the learning curve: short concepts only (swap_locations has 23 instructions), 2 training pairs
    c = json.loads((curve / "run.json").read_text())
    assert list(c["examples_sha256"]) == ["remove_bottom_obj"] and c["examples_sha256"]["remove_bottom_obj"].endswith(
        ":first2")
    r = json.loads((tmp_path / "res" / "r.json").read_text())
    assert {"date", "commit", "machine", "command"} <= set(r) and set(r["rows"]) == {main_row.name, curve.name}
    assert r["rows"][main_row.name]["row"] == "o1-predfix-0.5M" and r["rows"][curve.name]["row"] == "examples-2"
    report = (tmp_path / "REPORT.md").read_text()
    assert f"| {s['found']} of 2 | " in report and f"`{main_row.name}`" in report
    assert "| o1-uniform-0.5M |" in report and report.count("not run") >= 10  # rows not run say so
    # rerunning resumes: nothing is searched again
    lines = (main_row / "results.jsonl").read_text()
    assert main(_reproduce(tmp_path, "--rows", "o1-predfix-0.5M")) == 0
    assert (main_row / "results.jsonl").read_text() == lines
    # a row finished under a default since changed is kept as it is (and reported), not refused
    meta = json.loads((main_row / "run.json").read_text())
    meta["settings"]["filters"] = "network"
    (main_row / "run.json").write_text(json.dumps(meta))
    capsys.readouterr()
    assert main(_reproduce(tmp_path, "--rows", "o1-predfix-0.5M")) == 0
    assert "kept: " in capsys.readouterr().out and (main_row / "results.jsonl").read_text() == lines
    # unfinished, it is refused in one line: resuming would mix two settings in one run
    (main_row / "summary.json").unlink()
    assert main(_reproduce(tmp_path, "--rows", "o1-predfix-0.5M")) != 0
    assert "other settings" in capsys.readouterr().err and (main_row / "results.jsonl").read_text() == lines


def test_bench_reproduce_searches_a_rows_last_pass_anew_keeping_its_iterations(tmp_path, capsys):
    assert main(_reproduce(tmp_path, "--rows", "o1-predfix-0.5M")) == 0
    row = next((tmp_path / "runs").iterdir())
    lines = (row / "results.jsonl").read_text().splitlines()
    last = [line for line in lines if json.loads(line).get("last_pass")]
    assert last  # swap_locations is missed at this budget: the pass searched it
    found = json.loads((row / "summary.json").read_text())["found"]
    capsys.readouterr()
    assert main(_reproduce(tmp_path, "--rows", "o1-predfix-0.5M", "--redo-last-pass")) == 0
    assert "last-pass-0.jsonl" in capsys.readouterr().out
    assert (row / "last-pass-0.jsonl").read_text().splitlines() == last  # the earlier pass kept aside
    again = (row / "results.jsonl").read_text().splitlines()
    assert again[: len(lines) - len(last)] == [line for line in lines if line not in last]  # iterations kept
    redone = [json.loads(line) for line in again[len(lines) - len(last):]]
    old = [json.loads(line) for line in last]
    assert [(r["concept"], r["found"], r["program"]) for r in redone] == [
        (r["concept"], r["found"], r["program"]) for r in old]  # the same code searches the same
    assert {r["session"] for r in redone} == {len(json.loads((row / "run.json").read_text())["sessions"]) - 1}
    assert json.loads((row / "summary.json").read_text())["found"] == found
    # a last line cut by an interrupt is dropped with the pass; a bad line elsewhere is
    # refused in one line, and nothing is moved
    (row / "results.jsonl").write_text("\n".join(again) + '\n{"concept": "swap_lo')
    assert main(_reproduce(tmp_path, "--rows", "o1-predfix-0.5M", "--redo-last-pass")) == 0
    assert (row / "last-pass-1.jsonl").read_text().splitlines() == again[len(lines) - len(last):]
    good = (row / "results.jsonl").read_text()
    (row / "results.jsonl").write_text("not json\n" + good)
    capsys.readouterr()
    assert main(_reproduce(tmp_path, "--rows", "o1-predfix-0.5M", "--redo-last-pass")) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "results.jsonl" in err and not (row / "last-pass-2.jsonl").exists()
    assert (row / "summary.json").exists()
    (row / "results.jsonl").write_text(good)
    # a row with no finished last pass is left as it is
    (row / "summary.json").unlink()
    before = (row / "results.jsonl").read_text()
    assert main(_reproduce(tmp_path, "--rows", "o1-predfix-0.5M", "--redo-last-pass")) == 0
    assert (row / "results.jsonl").read_text() == before and not (row / "last-pass-2.jsonl").exists()


def test_bench_reproduce_refuses_an_unknown_row_or_scale(tmp_path, capsys):
    assert main(_reproduce(tmp_path, "--rows", "o2-magic")) == 2
    assert "unknown row(s): o2-magic" in capsys.readouterr().err
    assert main(_reproduce(tmp_path, "--rows", "examples-1", "--scale", "0")) == 2
    assert "argument --scale: 0 is out of range" in capsys.readouterr().err
