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
