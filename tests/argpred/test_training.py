"""Training the argument predictor: the loss falls, a resumed run ends in the same weights,
a diverged one keeps nothing; the weights on disk and the recall their card records."""

from __future__ import annotations

import json

import numpy as np
import pytest

from argpred import data as argdata
from argpred.features import pair_features
from argpred.predict import Predictor
from argpred.train import TrainSettings, train
from argpred.weights import load, save
from vccjax.errors import DataFileError
from vccjax.machine.scene import Scene, SceneObject


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
