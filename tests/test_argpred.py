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
from vccjax.program import parse
from vccjax.scene import Scene, SceneObject


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
    from vccjax.reference import RefMachine

    out = RefMachine(both).run(loop).output_scene()
    assert not argdata.indispensable(loop, [(both, out)])


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    folder = tmp_path_factory.mktemp("argdata")
    arrays = argdata.build_shard(seed=5, shard=0, size=24)
    np.savez_compressed(folder / "shard0000.npz", **arrays)
    manifest = {"format": argdata.FORMAT, "version": argdata.VERSION, "seed": 5, "shard": 24,
                "labels": [list(x) for x in argdata.LABELS], "max_objects": 8,
                "shards": {"shard0000.npz": argdata._sha(folder / "shard0000.npz")}}
    (folder / "manifest.json").write_text(json.dumps(manifest))
    return folder


def test_shards_are_seeded_and_data_loads_verified(tiny):
    again = argdata.build_shard(seed=5, shard=0, size=24)
    with np.load(tiny / "shard0000.npz") as z:
        assert all(np.array_equal(z[k], again[k]) for k in again)
    d = argdata.load(tiny)
    assert d["inputs"].shape == (24, 10, 9, 4) and d["labels"].shape == (24, len(argdata.LABELS))
    assert len(d["programs"]) == 24
    assert argdata.built(tiny) == {"programs": 24, "seed": 5, "joined": 0.0}  # `train --data` keeps them all
    assert argdata.built(tiny / "none") is None
    with pytest.raises(DataFileError, match="built with seed 5 and joined 0"):
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
    assert hist[-1]["train_bce"] < 0.7 * hist[0]["train_bce"]
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
    assert card["model"] == {"hidden": 4, "kernel": 3, "depth": 1}
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


def test_predicted_arguments_keep_only_those_that_pass():
    probs = {"set_color_attn": np.array([0.9, 0.6, 0.2, 0.1]), "fill_color": np.array([0.1, 0.2, 0.3, 0.54]),
             "set_shape_attn": np.array([0.55, 0.0, 0.0, 0.0, 0.0])}
    lp = argument_logp(probs)
    assert np.isclose(np.exp(lp["set_color_attn"][:2]).sum(), 1) and np.isinf(lp["set_color_attn"][2:]).all()
    assert lp["set_color_attn"][0] > lp["set_color_attn"][1]
    assert np.isinf(lp["fill_color"]).all()  # nothing passes: the instruction is left out
    assert lp["set_shape_attn"][0] == 0 and THRESHOLD == 0.55


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
    assert main(["argpred", "eval", "--concepts", "remove_bottom_obj,change_all_objs_color"]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert out[-1].startswith("recall: ") and 0 <= float(out[-1].split()[1]) <= 1


def test_induce_with_predicted_arguments(tmp_path, capsys, monkeypatch):
    from vcc.cli import main

    monkeypatch.setenv("VCCJAX_CACHE", "off")
    out = tmp_path / "pred"
    argv = ["induce", "--concepts", "change_target_obj_to_given_color,remove_bottom_obj", "--out", str(out),
            "--budget", "20000", "--iterations", "1", "--args", "predicted+fixation", "--quiet"]
    assert main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["found"] == 2 and summary["exact_on_all_test_pairs"] == 2
