"""Trained weights on disk: msgpack (flax.serialization, no pickle) beside a JSON card
with the model's settings, the labels and the sha256 of the msgpack bytes. Loading
checks all three and refuses a file that is cut, edited or made for another model.

An ensemble (`members` > 1: networks trained alike from different seeds, whose
probabilities are averaged) stores its parameters stacked on a leading axis."""

from __future__ import annotations

import hashlib
import json
from importlib import resources
from pathlib import Path

import jax
import jax.numpy as jnp
from flax import serialization

from argpred.data import LABELS
from argpred.features import CHANNELS, GRID
from argpred.model import ArgNet
from vccjax.errors import DataFileError

FORMAT, VERSION = "vccjax-argpred-weights", 1


def shipped_weights() -> Path:
    """The weights trained by `vcc argpred train` with its defaults, shipped in the package."""
    return Path(str(resources.files("argpred").joinpath("weights/argpred.msgpack")))


def init_params(model: ArgNet, seed: int = 0) -> dict:
    x = jnp.zeros((1, 2, CHANNELS, GRID, GRID), jnp.int8)
    return model.init(jax.random.PRNGKey(seed), x, jnp.ones((1, 2)))["params"]


def stack(members: list[dict]) -> dict:
    """Parameters of several members on one leading axis (what an ensemble file holds)."""
    return jax.tree.map(lambda *w: jnp.stack(w), *members)


def members_of(params: dict) -> int:
    """How many networks `params` holds (1 unless stacked by `stack`)."""
    return int(params["bias"].shape[0]) if params["bias"].ndim == 2 else 1


def save(path: str | Path, model: ArgNet, params: dict, info: dict | None = None) -> str:
    """Write `path` (msgpack) and `path.json` (the card); return the sha256. `params` of
    an ensemble are stacked (`stack`)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = serialization.to_bytes(jax.device_get(params))
    sha = hashlib.sha256(data).hexdigest()
    shape = {"hidden": model.hidden, "kernel": model.kernel, "depth": model.depth, "evidence": model.evidence,
             "members": members_of(params)}
    card = {"format": FORMAT, "version": VERSION, "model": shape,
            "labels": [list(x) for x in LABELS], "sha256": sha, **(info or {})}
    tmp = path.with_suffix(".tmp")
    tmp.write_bytes(data)
    tmp.replace(path)
    path.with_suffix(".json").write_text(json.dumps(card, indent=1))
    return sha


def load(path: str | Path | None = None) -> tuple[ArgNet, dict, dict]:
    """(model, params, card) from `path` (default: the shipped weights)."""
    path = Path(path) if path is not None else shipped_weights()
    card_path = path.with_suffix(".json")
    try:
        card = json.loads(card_path.read_text())
        data = path.read_bytes()
    except FileNotFoundError as e:
        raise DataFileError(f"{e.filename}: missing (train with `vcc argpred train`)") from None
    except json.JSONDecodeError as e:
        raise DataFileError(f"{card_path}: not JSON ({e})") from None
    if not isinstance(card, dict) or card.get("format") != FORMAT or card.get("version") != VERSION:
        raise DataFileError(f"{card_path}: not a {FORMAT} v{VERSION} card")
    if card.get("labels") != [list(x) for x in LABELS]:
        raise DataFileError(f"{card_path}: made for other labels than this vccjax predicts")
    if hashlib.sha256(data).hexdigest() != card.get("sha256"):
        raise DataFileError(f"{path}: sha256 differs from its card (corrupt or replaced)")
    try:
        model = ArgNet(hidden=int(card["model"]["hidden"]), kernel=int(card["model"]["kernel"]),
                       depth=int(card["model"].get("depth", 1)),
                       evidence=str(card["model"].get("evidence", "signed")))
        members = int(card["model"].get("members", 1))
        template = init_params(model) if members == 1 else stack([init_params(model)] * members)
        params = serialization.from_bytes(template, data)
    except (KeyError, TypeError, ValueError) as e:
        raise DataFileError(f"{path}: does not hold this model's weights ({e})") from None
    for a, b in zip(jax.tree.leaves(params), jax.tree.leaves(template)):
        if a.shape != b.shape:
            raise DataFileError(f"{path}: a weight of shape {a.shape} where the model has {b.shape}")
    return model, params, card
