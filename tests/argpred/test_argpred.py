"""Argument prediction: features, training data, training, weights on disk, and its use
by the search."""

from __future__ import annotations

import json

import numpy as np
import pytest

from argpred import data as argdata
from argpred.features import CHANNEL_NAMES, CHANNELS, GRID, pair_features
from argpred.predict import THRESHOLD, Predictor, argument_logp
from argpred.train import TrainSettings, train
from argpred.weights import load, save
from vccjax.errors import DataFileError
from vccjax.machine.program import check_loop_syntax, parse
from vccjax.machine.scene import Scene, SceneObject


def test_features_of_a_hand_built_pair_mean_what_the_channels_say():
    # a red square at the centre turns blue; a green circle at the top left stays
    before = Scene((SceneObject("square", "red", 0.5, 0.5, 0.1), SceneObject("circle", "green", 0.1, 0.1, 0.1)),
                   pointer=(0.9, 0.2))
    after = Scene((SceneObject("square", "blue", 0.5, 0.5, 0.1), SceneObject("circle", "green", 0.1, 0.1, 0.1)),
                  pointer=(0.9, 0.2))
    f = pair_features([(before, after)])
    assert f.shape == (1, CHANNELS, GRID, GRID) and len(CHANNEL_NAMES) == CHANNELS
    ch = {name: f[0, k] for k, name in enumerate(CHANNEL_NAMES)}
    assert ch["in:square"][7, 7] == 1 and ch["in:red"][7, 7] == 1  # floor(0.5 * 14) = 7 (row, column)
    assert ch["in:circle"][1, 1] == 1 and ch["in:green"][1, 1] == 1
    assert ch["in:pointer"][2, 12] == 1 and ch["in:pointer"].sum() == 1  # row from y = 0.2, column from x = 0.9
    assert ch["diff:red"][7, 7] == -1 and ch["diff:blue"][7, 7] == 1
    assert ch["diff:square"].sum() == 0 and ch["diff:green"].sum() == 0 and ch["diff:pointer"].sum() == 0
    assert ch["changed"][7, 7] == 1 and ch["changed"].sum() == 1
    # a move: gone from one cell, present in another
    moved = Scene((SceneObject("square", "red", 0.9, 0.5, 0.1), before.objects[1]), pointer=(0.9, 0.2))
    g = dict(zip(CHANNEL_NAMES, pair_features([(before, moved)])[0]))
    assert g["diff:square"][7, 7] == -1 and g["diff:square"][7, 12] == 1 and g["changed"].sum() == 2


def test_drawn_programs_pass_the_filters_and_are_labelled():
    rng = np.random.default_rng(3)
    pool = argdata.scene_pool(rng, 40)
    for _ in range(5):
        program, pairs = argdata.kept_program(rng, pool)
        assert len(pairs) == 10 and argdata.LENGTHS[0] <= len(program) <= argdata.LENGTHS[1]
        assert argdata.indispensable(program, pairs)
        assert all(a != b for a, b in pairs)  # every example changes
    labels = argdata.labels_of(parse("scene_parse; set_color_attn(red); top_down_attend; fill_color(blue)"))
    on = {argdata.LABELS[k] for k in np.nonzero(labels)[0]}
    assert on == {("set_color_attn", "red"), ("fill_color", "blue")}
    # a filter that changes nothing is dispensable: both squares would turn blue anyway
    both = Scene((SceneObject("square", "red", 0.3, 0.3, 0.1), SceneObject("square", "red", 0.7, 0.7, 0.1)))
    loop = parse("scene_parse; set_shape_attn(square); loop_start; top_down_attend; fill_color(blue); "
                 "next_object; loop_end")
    from vccjax.machine.reference import RefMachine

    out = RefMachine(both).run(loop).output_scene()
    assert not argdata.indispensable(loop, [(both, out)])


def test_shards_are_seeded_and_data_loads_verified(tiny):
    again = argdata.build_shard(seed=5, shard=0, size=24)
    with np.load(tiny / "shard0000.npz") as z:
        assert all(np.array_equal(z[k], again[k]) for k in again)
    d = argdata.load(tiny)
    assert d["inputs"].shape == (24, 10, 9, 4) and d["labels"].shape == (24, len(argdata.LABELS))
    assert len(d["programs"]) == 24
    # `train --data` keeps them all
    assert argdata.built(tiny) == {"programs": 24, "seed": 5, "joined": 0.0, "kind": "drawn"}
    assert argdata.built(tiny / "none") is None
    with pytest.raises(DataFileError, match="built with seed 5, joined 0.0, kind drawn"):
        argdata.build(tiny, 24, seed=6)  # refused, not rebuilt: nothing drawn is lost
    (tiny / "extra").mkdir(exist_ok=True)
    bad = tiny / "extra"
    (bad / "manifest.json").write_text(json.dumps({"format": "something else"}))
    with pytest.raises(DataFileError, match="not a vccjax-argpred-data"):
        argdata.load(bad)


def test_loss_falls_and_training_resumes_to_the_same_weights(tiny, tmp_path):
    d = argdata.load(tiny)
    settings = TrainSettings(hidden=8, epochs=6, batch=8, learning_rate=1e-2, validation=0.25)
    _, params, hist = train(d, settings, progress=False, log=lambda s: None)
    assert hist[-1]["train_loss"] < 0.7 * hist[0]["train_loss"]  # the objective Adam lowers (used labels weighted)
    # interrupted after 3 epochs, resumed from the checkpoint: the same weights
    ckpt = tmp_path / "w.ckpt"
    train(d, TrainSettings(**{**settings.__dict__, "epochs": 3}), checkpoint=ckpt, progress=False)
    with pytest.raises(ValueError, match="other settings"):
        train(d, TrainSettings(**{**settings.__dict__, "epochs": 3, "l1": 0.5}), checkpoint=ckpt, progress=False)
    fewer = {k: v[:20] for k, v in d.items()}
    with pytest.raises(ValueError, match="other data"):
        train(fewer, TrainSettings(**{**settings.__dict__, "epochs": 3}), checkpoint=ckpt, progress=False)
    import jax

    _, resumed, hist2 = train(d, settings, checkpoint=ckpt, progress=False, log=lambda s: None)
    assert len(hist2) == 6
    for a, b in zip(jax.tree.leaves(params), jax.tree.leaves(resumed)):
        np.testing.assert_allclose(np.asarray(a), np.asarray(b), rtol=1e-5, atol=1e-6)


def test_weights_round_trip_and_refuse_corrupt_or_foreign_files(tiny, tmp_path):
    d = argdata.load(tiny)
    model, params, _ = train(d, TrainSettings(hidden=4, epochs=1, batch=8), progress=False)
    path = tmp_path / "w.msgpack"
    save(path, model, params)
    p = Predictor(path)
    x = pair_features([(Scene((SceneObject("square", "red", 0.5, 0.5, 0.1),)),
                        Scene((SceneObject("square", "blue", 0.5, 0.5, 0.1),)))])
    probs = p.probabilities(x[None])
    assert probs.shape == (1, len(argdata.LABELS)) and ((probs >= 0) & (probs <= 1)).all()
    m2, params2, card = load(path)
    assert card["model"] == {"hidden": 4, "kernel": 3, "depth": 1, "evidence": "relu", "members": 1}
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(DataFileError, match="sha256 differs"):
        load(path)
    path.write_bytes(b"")
    card["sha256"] = __import__("hashlib").sha256(b"").hexdigest()
    path.with_suffix(".json").write_text(json.dumps(card))
    with pytest.raises(DataFileError, match="does not hold this model"):
        load(path)
    with pytest.raises(DataFileError, match="missing"):
        load(tmp_path / "none.msgpack")


def test_loop_programs_do_one_change_to_every_attended_object(tmp_path):
    folder = tmp_path / "loop"
    argdata.build(folder, 6, seed=3, progress=False, kind="loop")
    assert argdata.built(folder) == {"programs": 6, "seed": 3, "joined": 0.0, "kind": "loop"}
    d = argdata.load(folder)
    assert d["inputs"].shape == (6, 10, 9, 4)
    for text, labels in zip(d["programs"], d["labels"]):
        program = parse(text)
        check_loop_syntax(program)  # a whole loop: loop_start; top_down_attend; ...; next_object; loop_end
        steps = text.split("; ")
        assert steps[-1] == "loop_end" and steps[-2] == "next_object" and steps.count("loop_start") == 1
        before = steps[: steps.index("loop_start")]  # only a selection before the loop
        assert all(s.split("(")[0] in ("scene_parse", "set_shape_attn", "set_color_attn", "fixate") for s in before)
        assert np.array_equal(labels, argdata.labels_of(program))
    again = argdata.build_shard(3, 0, size=6, kind="loop")
    with np.load(folder / "shard0000.npz") as z:
        assert all(np.array_equal(z[k], again[k]) for k in again)
    with pytest.raises(DataFileError, match="kind loop"):
        argdata.build(folder, 6, seed=3, progress=False, kind="carry")  # another kind into a loop folder: refused


def test_carry_programs_are_seeded_two_attend_procedures_in_their_own_folder(tmp_path):
    folder = tmp_path / "carry"
    argdata.build(folder, 5, seed=2, progress=False, kind="carry")
    assert argdata.built(folder) == {"programs": 5, "seed": 2, "joined": 0.0, "kind": "carry"}
    d = argdata.load(folder)
    assert d["inputs"].shape == (5, 10, 9, 4) and len(d["programs"]) == 5
    for text in d["programs"]:  # pick, grab, then attend a second object and carry the first onto it
        steps = text.split("; ")
        assert steps.count("top_down_attend") == 2 and steps.count("grab_object") == 1
        assert steps.index("grab_object") < len(steps) - 1 - steps[::-1].index("top_down_attend")
    again = argdata.build_shard(2, 0, size=5, kind="carry")
    with np.load(folder / "shard0000.npz") as z:
        assert all(np.array_equal(z[k], again[k]) for k in again)
    with pytest.raises(DataFileError, match="kind carry"):
        argdata.build(folder, 5, seed=2, progress=False)  # a drawn build into a carry folder: refused
    with pytest.raises(ValueError, match="not joined"):
        argdata.build(tmp_path / "other", 5, seed=2, progress=False, kind="carry", joined=0.3)
    with pytest.raises(ValueError, match="unknown kind"):
        argdata.build(tmp_path / "other", 5, kind="enumerated")


def test_predicted_arguments_keep_only_those_that_pass():
    probs = {"set_color_attn": np.array([0.9, 0.6, 0.2, 0.1]), "fill_color": np.array([0.1, 0.2, 0.3, 0.54]),
             "set_shape_attn": np.array([0.55, 0.0, 0.0, 0.0, 0.0])}
    lp = argument_logp(probs)
    assert np.isclose(np.exp(lp["set_color_attn"][:2]).sum(), 1) and np.isinf(lp["set_color_attn"][2:]).all()
    assert lp["set_color_attn"][0] > lp["set_color_attn"][1]
    assert np.isinf(lp["fill_color"]).all()  # nothing passes: the instruction is left out
    assert lp["set_shape_attn"][0] == 0 and THRESHOLD == 0.55
    higher = argument_logp(probs, threshold=0.6)  # a higher threshold: set_shape_attn left out, green kept
    assert np.isinf(higher["set_shape_attn"]).all() and np.isfinite(higher["set_color_attn"][:2]).all()
    assert np.isclose(np.exp(higher["set_color_attn"][:2]).sum(), 1)


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


def _copy_shipped(folder, keep_recall: bool = True):
    """The shipped weights copied to `folder` (the card without `recall` unless kept)."""
    from argpred.weights import shipped_weights

    src = shipped_weights()
    dst = folder / "w.msgpack"
    dst.write_bytes(src.read_bytes())
    card = json.loads(src.with_suffix(".json").read_text())
    if not keep_recall:
        card.pop("recall", None)
    dst.with_suffix(".json").write_text(json.dumps(card))
    return dst


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
    copy = _copy_shipped(tmp_path, keep_recall=False)
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


def _one_error_line(capsys, fragment: str) -> None:
    err = capsys.readouterr().err
    assert err.startswith("vcc") and ": error: " in err and err.count("\n") == 1 and fragment in err, err


def test_a_higher_threshold_passes_fewer_arguments(tmp_path):
    """Recall and extra arguments at two thresholds, on a few concepts: every argument
    passing 0.6 passes 0.55, so 0.6 recalls no concept 0.55 misses and passes no more
    extra arguments; the result file says which threshold it measured."""
    from vcc.cli import main

    concepts = "change_all_objs_color,move_all_objs_down,change_red_objs_color,remove_bottom_obj,move_to_top_edge"
    runs = {}
    for t in ("0.55", "0.6"):
        out = tmp_path / f"r{t}.json"
        assert main(["argpred", "eval", "--concepts", concepts, "--threshold", t, "--out", str(out), "--show", "0"]) == 0
        runs[t] = json.loads(out.read_text())
        assert runs[t]["threshold"] == float(t) and ("--threshold" in runs[t]["command"]) == (t != "0.55")
    low, high = runs["0.55"], runs["0.6"]
    assert set(low["missed"]) <= set(high["missed"]) and high["recalled"] <= low["recalled"]
    assert all(high["mean_extra_arguments"][f] <= v for f, v in low["mean_extra_arguments"].items())


def test_fill_arguments_from_the_gained_colours_recall_the_fills_and_pass_no_extra_one(tmp_path):
    """`--fill gained` (what the search takes by default): every fill_color argument a
    reference program uses is recalled and none it does not use passes; the filters are
    the network's either way."""
    from vcc.cli import main

    concepts = ("change_all_objs_color,move_all_objs_down,change_red_objs_color,remove_bottom_obj,"
                "move_right_most_obj_to_top_edge_AND_change_color")
    runs = {}
    for fill in ("predicted", "gained"):
        out = tmp_path / f"{fill}.json"
        assert main(["argpred", "eval", "--concepts", concepts, "--fill", fill, "--out", str(out), "--show", "0"]) == 0
        runs[fill] = json.loads(out.read_text())
        assert runs[fill]["fill"] == fill and ("--fill" in runs[fill]["command"]) == (fill == "gained")
    gained, network = runs["gained"], runs["predicted"]
    assert gained["mean_extra_arguments"]["fill_color"] == 0
    assert not any("fill_color" in miss for miss in gained["missed"].values())
    for f in ("set_shape_attn", "set_color_attn"):
        assert gained["mean_extra_arguments"][f] == network["mean_extra_arguments"][f]


def test_filters_the_objects_acted_on_rule_out_drop_extra_filters_and_no_used_one(tmp_path):
    """`--filters acted` (what the search takes by default) on concepts that act on every
    object and on filtered ones: the loops lose the filters the network passes them,
    and no concept loses a filter value its program uses."""
    from vcc.cli import main

    concepts = "change_all_objs_color,move_all_objs_down,change_red_objs_color,move_all_yellow_left"
    runs = {}
    for filters in ("network", "acted"):
        out = tmp_path / f"{filters}.json"
        assert main(["argpred", "eval", "--concepts", concepts, "--fill", "gained", "--filters", filters,
                     "--out", str(out), "--show", "0"]) == 0
        runs[filters] = json.loads(out.read_text())
        assert runs[filters]["filters"] == filters and ("--filters" in runs[filters]["command"]) == (filters == "acted")
    acted, network = runs["acted"], runs["network"]
    assert acted["recalled"] == network["recalled"]
    for c in ("change_all_objs_color", "move_all_objs_down"):
        assert c in network["extra_arguments"] and c not in acted["extra_arguments"]
    assert sum(acted["mean_extra_arguments"][f] for f in ("set_shape_attn", "set_color_attn")) < \
        sum(network["mean_extra_arguments"][f] for f in ("set_shape_attn", "set_color_attn"))


def test_argpred_commands_refuse_bad_options_in_one_line_writing_nothing(tmp_path, capsys, monkeypatch):
    from argpred import cli as argcli
    from vcc.cli import main

    monkeypatch.setattr(argcli, "DEFAULT_DATA", tmp_path / "default-data")  # where train would draw its data
    w, d, res = tmp_path / "new.msgpack", tmp_path / "data", tmp_path / "r.json"
    train = ["argpred", "train", "--out", str(w), "--quiet"]
    for argv, fragment in [
        (train + ["--epochs", "0"], "argument --epochs: 0 is out of range"),
        (train + ["--lr", "nan"], "argument --lr: nan is not a finite number"),
        (train + ["--lr", "-0.1"], "argument --lr: -0.1 is out of range"),
        (train + ["--positive-weight", "inf"], "argument --positive-weight: inf is not a finite number"),
        (train + ["--l1", "-1"], "argument --l1: -1 is out of range"),
        (train + ["--members", "0"], "argument --members: 0 is out of range"),
        (train + ["--batch", "0"], "argument --batch: 0 is out of range"),
        (train + ["--programs", "0"], "argument --programs: 0 is out of range"),
        (train + ["--joined", "1.5"], "argument --joined: 1.5 is out of range"),
        (train + ["--carry", "-1"], "argument --carry: -1 is out of range"),
        (train + ["--loops", "-1"], "argument --loops: -1 is out of range"),
        (train + ["--pool", "everywhere"], "argument --pool: invalid choice"),
        (train + ["--pool", "hidden", "--hidden", "0"], "--pool hidden pools the hidden channels"),
        (["argpred", "train", "--out", str(tmp_path), "--quiet"], "write .msgpack"),
        (["argpred", "data", "--out", str(d), "--programs", "0"], "argument --programs: 0 is out of range"),
        (["argpred", "data", "--out", str(d), "--joined", "nan"], "argument --joined: nan is not a finite number"),
        (["argpred", "eval", "--concepts", "", "--out", str(res)], "has an empty name"),
        (["argpred", "eval", "--concepts", "no_such", "--out", str(res)], "unknown concept(s): no_such"),
        (["argpred", "eval", "--show", "-1", "--out", str(res)], "argument --show: -1 is out of range"),
        (["argpred", "eval", "--record", "--concepts", "remove_bottom_obj"], "--record keeps the weights' own recall"),
        (["argpred", "eval", "--record", "--threshold", "0.6"], "--record keeps the weights' own recall"),
        (["argpred", "eval", "--record", "--fill", "gained"], "--record keeps the weights' own recall"),
        (["argpred", "eval", "--fill", "both", "--out", str(res)], "argument --fill: invalid choice"),
        (["argpred", "eval", "--record", "--filters", "acted"], "--record keeps the weights' own recall"),
        (["argpred", "eval", "--filters", "both", "--out", str(res)], "argument --filters: invalid choice"),
        (["argpred", "eval", "--threshold", "0", "--out", str(res)], "argument --threshold: 0 is out of range"),
        (["argpred", "data", "--out", str(d), "--kind", "loops"], "argument --kind: invalid choice"),
        (["argpred", "eval", "--weights", str(tmp_path / "none.msgpack"), "--out", str(res)], "none.msgpack: missing"),
    ]:
        assert main(argv) == 2, argv
        _one_error_line(capsys, fragment)
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing drawn, trained or written
    # corrupt weights: refused, and --record leaves the card as it was
    copy = _copy_shipped(tmp_path)
    data = bytearray(copy.read_bytes())
    data[len(data) // 3] ^= 0x01
    copy.write_bytes(bytes(data))
    card = copy.with_suffix(".json").read_bytes()
    good = json.loads(card)
    assert main(["argpred", "eval", "--weights", str(copy), "--record", "--out", str(res)]) == 2
    _one_error_line(capsys, "sha256 differs from its card")
    assert copy.with_suffix(".json").read_bytes() == card
    copy.with_suffix(".json").write_text("{cut")
    assert main(["argpred", "eval", "--weights", str(copy), "--out", str(res)]) == 2
    _one_error_line(capsys, "w.json: not JSON")
    import hashlib

    import msgpack

    for body in (msgpack.packb(5), msgpack.packb([1, 2]), b""):  # the card's sha256 matches, the content is not weights
        copy.write_bytes(body)
        copy.with_suffix(".json").write_text(json.dumps({**good, "sha256": hashlib.sha256(body).hexdigest()}))
        assert main(["argpred", "eval", "--weights", str(copy), "--out", str(res)]) == 2
        _one_error_line(capsys, "does not hold this model's weights")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w.json", "w.msgpack"]


def test_train_records_the_recall_of_what_it_trained_in_the_card(tiny, tmp_path, capsys):
    """`vcc argpred train` ends by measuring the new weights on all the concepts and keeping
    that in their card; measured again on a few concepts, they miss what the card says."""
    import shutil

    from argpred.recall import measure
    from vcc.cli import main
    from vccjax.world.concepts import concept_names

    data = tmp_path / "data"
    shutil.copytree(tiny, data)
    w = tmp_path / "w.msgpack"
    assert main(["argpred", "train", "--data", str(data), "--epochs", "1", "--members", "1", "--carry", "0",
                 "--hidden", "4", "--batch", "8", "--workers", "1", "--out", str(w), "--quiet"]) == 0
    printed = capsys.readouterr().out
    rec = load(w)[2]["recall"]
    assert rec["concepts"] == len(concept_names()) and rec["recalled"] == rec["concepts"] - len(rec["missed"])
    assert f"concepts recalled: {rec['recalled']} of {rec['concepts']}" in printed
    some = concept_names()[::50]
    r, _ = measure(w, some)
    assert set(r["missed"]) == set(rec["missed"]) & set(some)
    assert all(r["missed"][c] == rec["missed"][c] for c in r["missed"])


def test_induce_with_predicted_arguments(tmp_path, capsys, monkeypatch):
    from vcc.cli import main

    monkeypatch.setenv("VCCJAX_CACHE", "off")
    out = tmp_path / "pred"
    argv = ["induce", "--concepts", "change_target_obj_to_given_color,remove_bottom_obj", "--out", str(out),
            "--budget", "20000", "--iterations", "1", "--args", "predicted+fixation", "--quiet"]
    assert main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["found"] == 2 and summary["exact_on_all_test_pairs"] == 2


def test_training_that_diverges_stops_and_writes_no_checkpoint(tiny, tmp_path, monkeypatch):
    """A non-finite loss (here forced) ends training with one clear error; nothing of the
    diverged weights is kept."""
    import argpred.train as tr

    real = tr._step

    def diverged(*args):
        params, opt_state, bce, weighted = real(*args)
        return params, opt_state, bce, float("nan")

    monkeypatch.setattr(tr, "_step", diverged)
    ckpt = tmp_path / "c.ckpt"
    with pytest.raises(ValueError, match="training diverged at epoch 1"):
        train(argdata.load(tiny), TrainSettings(hidden=0, kernel=1, epochs=1, batch=24), checkpoint=ckpt, progress=False)
    assert not ckpt.exists()
