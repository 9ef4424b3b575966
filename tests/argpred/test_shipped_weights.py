"""The shipped weights: they read a colour change and recall what their card records."""

from __future__ import annotations

import json

import pytest

from argpred.predict import THRESHOLD, Predictor
from argpred.weights import load
from tests.argpred.shipped_copy import copy_shipped
from vccjax.machine.scene import Scene, SceneObject


def test_shipped_weights_load_and_read_a_colour_change(capsys):
    from vcc.cli import main

    p = Predictor()  # the shipped weights, verified against their card
    pairs = []
    for k in range(10):
        x = 0.15 + 0.07 * k
        pairs.append((Scene((SceneObject("square", "red", x, 0.3, 0.1), SceneObject("circle", "green", x, 0.7, 0.1))),
                      Scene((SceneObject("square", "blue", x, 0.3, 0.1), SceneObject("circle", "green", x, 0.7, 0.1)))))
    probs = p.for_pairs(pairs)
    assert probs["fill_color"][1:].argmax() + 1 == 2  # blue, of the colours not already there
    assert probs["fill_color"][2] >= THRESHOLD
    two = ["remove_bottom_obj", "change_all_objs_color"]
    assert main(["argpred", "eval", "--concepts", ",".join(two)]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    recalled = [c for c in two if c not in p.card["recall"]["missed"]]  # what the card's measurement says
    assert out[-2:] == [f"concepts recalled: {len(recalled)} of 2", f"recall: {len(recalled) / 2:.4f}"]


def test_shipped_weights_recall_what_their_card_records(tmp_path, capsys):
    """The shipped weights, measured again on all 546 concepts (7 s), recall what their card
    recorded when they were made; `eval --record` writes that record into a card that lacks
    it (as the shipped one's was) without touching the weights, and `--out` the result."""
    import datetime
    from pathlib import Path

    from argpred.weights import shipped_weights
    from vcc.cli import main
    from vccjax.world.concepts import concept_names

    shipped = json.loads(shipped_weights().with_suffix(".json").read_text())
    card = shipped["recall"]  # a card without it: KeyError, the test fails
    copy = copy_shipped(tmp_path, keep_recall=False)
    assert "recall" not in load(copy)[2]  # an older card loads as before
    out = tmp_path / "res" / "recall.json"
    assert main(["argpred", "eval", "--weights", str(copy), "--record", "--out", str(out), "--show", "0"]) == 0
    printed = capsys.readouterr().out.strip().splitlines()
    r = json.loads(out.read_text())
    # measured now == recorded then
    assert r["concepts"] == card["concepts"] == len(concept_names())
    assert r["recalled"] == card["recalled"] and r["missed"] == card["missed"]
    assert r["recall"] == card["recall"] == r["recalled"] / r["concepts"]
    for f, v in card["mean_extra_arguments"].items():
        assert r["mean_extra_arguments"][f] == pytest.approx(v, abs=1e-9)
    assert r["recalled"] == r["concepts"] - len(r["missed"])
    assert printed[-2:] == [f"concepts recalled: {r['recalled']} of {r['concepts']}", f"recall: {r['recall']:.4f}"]
    # the result file says what was measured, with what, when and how
    assert r["weights_sha256"] == shipped["sha256"] and r["members"] == shipped["model"]["members"]
    assert r["command"] == f"vcc argpred eval --weights {copy} --out {out} --record"
    assert r["benchmark"] == "argpred-recall" and r["seconds"] > 0
    now = datetime.datetime.now(datetime.timezone.utc)
    assert abs(datetime.datetime.fromisoformat(r["date"]) - now).total_seconds() < 600
    # --record: the copy's card now holds the same record; its weights are the same bytes
    _, _, new = load(copy)
    assert new["recall"]["recalled"] == card["recalled"] and new["recall"]["missed"] == card["missed"]
    assert new["recall"]["command"] == f"vcc argpred eval --weights {copy}" and new["sha256"] == shipped["sha256"]
    assert copy.read_bytes() == shipped_weights().read_bytes()
    assert {k: v for k, v in new.items() if k != "recall"} == {k: v for k, v in shipped.items() if k != "recall"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["res", "w.json", "w.msgpack"]  # no temporary left
    # the committed result that README cites is of these weights and says the same
    committed = json.loads((Path(__file__).parents[2] / "benchmarks" / "results" / "argpred-recall.json").read_text())
    assert committed["weights_sha256"] == shipped["sha256"], "benchmarks/results/argpred-recall.json: rerun it"
    assert (committed["recalled"], committed["concepts"], committed["missed"]) == (r["recalled"], r["concepts"],
                                                                                   r["missed"])
