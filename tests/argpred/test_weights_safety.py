"""Weights on disk are never non-finite, never claim sizes without bound, and a save
killed between writing its card and its weights is finished (or undone) on load."""

from __future__ import annotations

import hashlib
import json

import jax
import numpy as np
import pytest
from flax import serialization

from argpred.model import ArgNet
from argpred.weights import _pending, init_params, load, save
from vccjax.errors import DataFileError

SMALL = ArgNet(hidden=0, kernel=1, depth=1)


def test_a_save_refuses_non_finite_weights_and_writes_nothing(tmp_path):
    params = init_params(SMALL)
    bad = jax.tree.map(lambda w: np.full(np.shape(w), np.nan), params)
    with pytest.raises(ValueError, match="not all finite"):
        save(tmp_path / "w.msgpack", SMALL, bad)
    assert list(tmp_path.iterdir()) == []


def test_a_load_refuses_non_finite_weights_even_when_the_card_matches(tmp_path):
    path = tmp_path / "w.msgpack"
    save(path, SMALL, init_params(SMALL))
    params = jax.tree.map(lambda w: np.full(np.shape(w), np.inf, np.float32), init_params(SMALL))
    data = serialization.to_bytes(params)
    path.write_bytes(data)
    card = json.loads(path.with_suffix(".json").read_text())
    card["sha256"] = hashlib.sha256(data).hexdigest()  # a card forged to match
    path.with_suffix(".json").write_text(json.dumps(card))
    with pytest.raises(DataFileError, match="not finite"):
        load(path)


def test_a_card_claiming_a_huge_model_is_refused_before_anything_is_allocated(tmp_path):
    path = tmp_path / "w.msgpack"
    save(path, SMALL, init_params(SMALL))
    card = json.loads(path.with_suffix(".json").read_text())
    card["model"]["hidden"] = 10**9
    path.with_suffix(".json").write_text(json.dumps(card))
    with pytest.raises(DataFileError, match="hidden 1000000000 outside"):
        load(path)


@pytest.mark.parametrize("weights_replaced", [True, False])
def test_a_save_killed_between_card_and_weights_is_finished_or_undone(tmp_path, weights_replaced):
    """The pending card is written first: if the weights were replaced after it, the
    load finishes the save; if not, the old pair stays and the pending card goes."""
    path = tmp_path / "w.msgpack"
    save(path, SMALL, init_params(SMALL, seed=0))
    old_bytes, old_card = path.read_bytes(), path.with_suffix(".json").read_text()
    newer = tmp_path / "newer.msgpack"
    save(newer, SMALL, init_params(SMALL, seed=1))
    _pending(path).write_text(newer.with_suffix(".json").read_text())  # the kill came after this write
    if weights_replaced:
        path.write_bytes(newer.read_bytes())  # ... and after this one
    _, params, card = load(path)
    assert not _pending(path).exists()
    want = newer if weights_replaced else None
    assert card["sha256"] == hashlib.sha256((want or path).read_bytes()).hexdigest()
    if not weights_replaced:
        assert path.read_bytes() == old_bytes and path.with_suffix(".json").read_text() == old_card
