"""The network's variants: how examples' evidence is summed, how the grid is pooled, and
ensembles of members: what each lets an example say, and that each round-trips."""

from __future__ import annotations

import json

import numpy as np
import pytest

from argpred import data as argdata
from argpred.features import pair_features
from argpred.model import ArgNet
from argpred.predict import Predictor
from argpred.train import TrainSettings, train
from argpred.weights import init_params, load, save
from vccjax.errors import DataFileError
from vccjax.machine.scene import Scene, SceneObject


def test_pooling_the_hidden_channels_weighs_the_whole_grid_and_round_trips(tiny, tmp_path):
    """pool="hidden": each example's logits are a dense layer of its hidden channels'
    maxima over the grid (so a unit firing anywhere can lower a label), as computed here
    by hand; the card says so and the weights load back as that model."""
    import jax
    import jax.numpy as jnp

    from argpred.features import features_from_cells

    d = argdata.load(tiny)
    model, params, _ = train(d, TrainSettings(hidden=4, epochs=1, batch=8, pool="hidden"), progress=False)
    x = jnp.asarray(features_from_cells(d["inputs"][:3], d["outputs"][:3]))
    h = jnp.moveaxis(x.astype(jnp.float32), -3, -1)
    conv = params["conv_hidden"]
    h = jax.nn.relu(jax.lax.conv_general_dilated(h.reshape(-1, *h.shape[2:]), conv["kernel"], (1, 1), "SAME",
                                                 dimension_numbers=("NHWC", "HWIO", "NHWC")) + conv["bias"])
    per_example = jax.nn.relu(h.max(axis=(1, 2)) @ params["dense_out"]["kernel"]).reshape(3, 10, -1)
    by_hand = per_example.sum(axis=1) + params["bias"]
    np.testing.assert_allclose(np.asarray(model.apply({"params": params}, x, jnp.ones((3, 10)))),
                               np.asarray(by_hand), rtol=1e-5, atol=1e-5)
    save(tmp_path / "p.msgpack", model, params)
    m2, _, card = load(tmp_path / "p.msgpack")
    assert card["model"]["pool"] == "hidden" and m2.pool == "hidden"
    card["model"]["pool"] = "everywhere"
    (tmp_path / "p.json").write_text(json.dumps(card))
    with pytest.raises(DataFileError, match="pool 'everywhere'"):
        load(tmp_path / "p.msgpack")

def test_relu_evidence_lets_an_example_that_shows_nothing_say_nothing(tiny):
    import jax.numpy as jnp

    d = argdata.load(tiny)
    from argpred.features import features_from_cells

    x = jnp.asarray(features_from_cells(d["inputs"][:4], d["outputs"][:4]))  # (4, 10, 21, 15, 15)
    mask7 = jnp.ones((4, 10)).at[:, 7:].set(0)
    model, params, _ = train(d, TrainSettings(hidden=4, epochs=2, batch=8), progress=False)  # relu: the default
    seven = model.apply({"params": params}, x, mask7)
    ten = model.apply({"params": params}, x, jnp.ones((4, 10)))
    assert (np.asarray(ten) >= np.asarray(seven) - 1e-6).all()  # more examples can only add evidence
    # every position's logit below zero (positive hidden units, negative output kernel): under
    # the paper's signed sum the three examples added lower every label; under relu they say nothing
    import jax

    for evidence, lowered in (("signed", True), ("relu", False)):
        m = ArgNet(hidden=4, evidence=evidence)
        p = jax.tree.map(lambda w: w, init_params(m, 0))
        p["conv_hidden"]["bias"] = jnp.ones_like(p["conv_hidden"]["bias"])  # every hidden unit > 0 everywhere
        p["conv_out"]["kernel"] = -jnp.abs(p["conv_out"]["kernel"])
        seven = np.asarray(m.apply({"params": p}, x, mask7))
        ten = np.asarray(m.apply({"params": p}, x, jnp.ones((4, 10))))
        assert (ten < seven - 1e-6).all() if lowered else np.array_equal(ten, seven)

def test_shown_evidence_hears_an_example_only_on_values_its_objects_show():
    import jax.numpy as jnp

    from argpred.data import LABELS
    from argpred.model import shown

    # input: a red square and a green circle; output: the square turned blue
    before = Scene((SceneObject("square", "red", 0.5, 0.5, 0.1), SceneObject("circle", "green", 0.1, 0.1, 0.1)))
    after = Scene((SceneObject("square", "blue", 0.5, 0.5, 0.1), before.objects[1]))
    gate = dict(zip(LABELS, np.asarray(shown(jnp.asarray(pair_features([(before, after)])))[0])))
    want = {("set_shape_attn", "square"), ("set_shape_attn", "circle"), ("set_color_attn", "red"),
            ("set_color_attn", "green"), ("fill_color", "blue"), ("fill_color", "green")}  # red left the output
    assert {k for k, v in gate.items() if v == 1} == want and set(gate.values()) == {0.0, 1.0}
    # a network whose every example says "no": the examples that show no such value are not heard
    m = ArgNet(hidden=4, evidence="shown")
    p = init_params(m, 0)
    p["conv_hidden"]["bias"] = jnp.ones_like(p["conv_hidden"]["bias"])
    p["conv_out"]["kernel"] = -jnp.abs(p["conv_out"]["kernel"])
    one = jnp.asarray(pair_features([(before, after)]))[None]
    two = jnp.asarray(pair_features([(before, after), (before, after)]))[None]
    l1 = np.asarray(m.apply({"params": p}, one, jnp.ones((1, 1))))[0]
    l2 = np.asarray(m.apply({"params": p}, two, jnp.ones((1, 2))))[0]
    heard = np.array([k in want for k in LABELS])
    assert (l2[heard] < l1[heard] - 1e-6).all()  # a second example showing the value counts against it
    assert np.array_equal(l2[~heard], l1[~heard]) and np.array_equal(l1[~heard], np.asarray(p["bias"])[~heard])
    with pytest.raises(ValueError, match="unknown evidence"):
        ArgNet(hidden=4, evidence="maybe").apply({"params": p}, one, jnp.ones((1, 1)))

def test_an_ensemble_averages_its_members_and_round_trips(tiny, tmp_path):
    from argpred.train import train_members
    from argpred.weights import members_of

    d = argdata.load(tiny)
    settings = TrainSettings(hidden=4, epochs=2, batch=8)
    model, stacked, histories = train_members(d, settings, 2, checkpoint=tmp_path / "e.ckpt", progress=False)
    assert members_of(stacked) == 2 and len(histories) == 2
    assert (tmp_path / "e.m0.ckpt").exists() and (tmp_path / "e.m1.ckpt").exists()  # each resumable
    save(tmp_path / "e.msgpack", model, stacked)
    _, _, card = load(tmp_path / "e.msgpack")
    assert card["model"]["members"] == 2
    import jax

    from argpred.features import features_from_cells

    x = features_from_cells(d["inputs"][:3], d["outputs"][:3])
    singles = []
    for k in range(2):
        save(tmp_path / f"m{k}.msgpack", model, jax.tree.map(lambda w, k=k: w[k], stacked))
        singles.append(Predictor(tmp_path / f"m{k}.msgpack").probabilities(x))
    np.testing.assert_allclose(Predictor(tmp_path / "e.msgpack").probabilities(x), np.mean(singles, axis=0),
                               rtol=1e-5, atol=1e-6)
    # member k is the single network trained from seed + k
    _, alone, _ = train(d, TrainSettings(hidden=4, epochs=2, batch=8, seed=1), progress=False)
    for a, b in zip(jax.tree.leaves(alone), jax.tree.leaves(jax.tree.map(lambda w: w[1], stacked))):
        np.testing.assert_allclose(np.asarray(a), np.asarray(b), rtol=1e-5, atol=1e-6)
