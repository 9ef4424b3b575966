"""Trained weights on disk: msgpack (flax.serialization, no pickle) beside a JSON card
with the model's settings, the labels and the sha256 of the msgpack bytes. Loading
checks all three and refuses a file that is cut, edited or made for another model.

An ensemble (`members` > 1: networks trained alike from different seeds, whose
probabilities are averaged) stores its parameters stacked on a leading axis.

A card may also hold `recall`: what `vcc argpred eval` measured on these weights over
the 546 concepts (`argpred.recall.card_record`), written by `vcc argpred train` after
training or by `vcc argpred eval --record` (`record`, which leaves the msgpack bytes as
they are). Cards without it (older weights) load as before."""

from __future__ import annotations

import hashlib
import json
from importlib import resources
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
from flax import serialization

from argpred.data import LABELS
from argpred.features import CHANNELS, GRID
from argpred.model import EVIDENCE, ArgNet
from vccjax import files
from vccjax.errors import DataFileError

FORMAT, VERSION = "vccjax-argpred-weights", 1
MAX_HIDDEN = 4096  # the largest hidden size a card may claim


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
             "members": members_of(params), **({"pool": model.pool} if model.pool != "labels" else {})}
    card = {"format": FORMAT, "version": VERSION, "model": shape,
            "labels": [list(x) for x in LABELS], "sha256": sha, **(info or {})}
    if not all(bool(np.isfinite(np.asarray(w)).all()) for w in jax.tree.leaves(params)):
        raise ValueError(f"{path}: refusing to write weights that are not all finite")
    # The card is written first under a pending name, then the weights, then the card is
    # renamed into place: a kill in between leaves a pending card that `load` finishes.
    files.write_whole(_pending(path), json.dumps(card, indent=1))
    files.write_whole(path, data)
    _pending(path).replace(path.with_suffix(".json"))
    return sha


def _pending(path: Path) -> Path:
    return path.with_name(path.name + ".card-pending.json")


def _finish_pending(path: Path, data: bytes) -> None:
    """A save killed between its renames: keep the pending card if it is the weights'."""
    pending = _pending(path)
    if not pending.exists():
        return
    try:
        sha = json.loads(pending.read_text()).get("sha256")
    except (OSError, ValueError, AttributeError):
        sha = None
    if sha == hashlib.sha256(data).hexdigest():
        pending.replace(path.with_suffix(".json"))
    else:
        pending.unlink(missing_ok=True)  # killed before the weights were replaced


def _write_card(path: Path, card: dict) -> None:
    """The card beside `path`, replaced whole."""
    files.write_whole(path.with_suffix(".json"), json.dumps(card, indent=1))


def record(path: str | Path | None = None, **fields) -> dict:
    """Add `fields` to the card of the weights at `path` (default: the shipped weights),
    after checking card and weights as `load` does; the weights file is not rewritten, so
    its bytes and sha256 stay the same. Returns the new card."""
    path = Path(path) if path is not None else shipped_weights()
    reserved = {"format", "version", "model", "labels", "sha256"} & set(fields)
    if reserved:
        raise ValueError(f"a card's {', '.join(sorted(reserved))} come from the weights themselves")
    _, _, card = load(path)
    card = {**card, **fields}
    _write_card(path, card)
    return card


def load(path: str | Path | None = None) -> tuple[ArgNet, dict, dict]:
    """(model, params, card) from `path` (default: the shipped weights)."""
    path = Path(path) if path is not None else shipped_weights()
    card_path = path.with_suffix(".json")
    try:
        data = path.read_bytes()
        _finish_pending(path, data)
        card = json.loads(card_path.read_text())
    except FileNotFoundError as e:
        raise DataFileError(f"{e.filename}: missing (train with `vcc argpred train`)") from None
    except IsADirectoryError as e:
        raise DataFileError(f"{e.filename}: a folder, not weights") from None
    except (ValueError, RecursionError) as e:
        raise DataFileError(f"{card_path}: not JSON ({str(e)[:80]})") from None
    if not isinstance(card, dict) or card.get("format") != FORMAT or card.get("version") != VERSION:
        raise DataFileError(f"{card_path}: not a {FORMAT} v{VERSION} card")
    if card.get("labels") != [list(x) for x in LABELS]:
        raise DataFileError(f"{card_path}: made for other labels than this vccjax predicts")
    if hashlib.sha256(data).hexdigest() != card.get("sha256"):
        raise DataFileError(f"{path}: sha256 differs from its card (corrupt or replaced)")
    try:
        model = ArgNet(hidden=int(card["model"]["hidden"]), kernel=int(card["model"]["kernel"]),
                       depth=int(card["model"].get("depth", 1)),
                       evidence=str(card["model"].get("evidence", "signed")),
                       pool=str(card["model"].get("pool", "labels")))
        members = int(card["model"].get("members", 1))
        if model.pool not in ("labels", "hidden") or model.evidence not in EVIDENCE:
            raise ValueError(f"model pool {model.pool!r} / evidence {model.evidence!r} unknown")
        for name, value, low, top in (("hidden", model.hidden, 0, MAX_HIDDEN), ("kernel", model.kernel, 1, 15),
                                      ("depth", model.depth, 1, 8), ("members", members, 1, 64)):
            if not low <= value <= top:  # a card may not make us allocate without bound
                raise ValueError(f"model {name} {value} outside {low}..{top}")
        template = init_params(model) if members == 1 else stack([init_params(model)] * members)
        params = serialization.from_bytes(template, data)
    except (KeyError, TypeError, ValueError, AttributeError) as e:  # AttributeError: msgpack of a number or list
        raise DataFileError(f"{path}: does not hold this model's weights ({e})") from None
    for a, b in zip(jax.tree.leaves(params), jax.tree.leaves(template)):
        if a.shape != b.shape:
            raise DataFileError(f"{path}: a weight of shape {a.shape} where the model has {b.shape}")
        if not np.isfinite(np.asarray(a)).all():
            raise DataFileError(f"{path}: holds weights that are not finite (NaN or infinity)")
    return model, params, card
