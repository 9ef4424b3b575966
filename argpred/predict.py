"""Argument probabilities for a concept's example pairs, and what the search takes
from them: an argument passes at probability >= 0.55 (the paper's threshold); an
instruction none of whose arguments pass is left out of the search."""

from __future__ import annotations

import functools
from collections.abc import Sequence
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from argpred.data import LABELS, PREDICTED
from argpred.features import pair_features
from argpred.weights import load, members_of
from vccjax.machine.instructions import arg_domain
from vccjax.machine.scene import Scene

THRESHOLD = 0.55


class Predictor:
    def __init__(self, weights: str | Path | None = None):
        self.model, self.params, self.card = load(weights)

        def one(p, x, m):
            return jax.nn.sigmoid(self.model.apply({"params": p}, x, m))

        if members_of(self.params) > 1:  # an ensemble: the members' mean probability
            self._apply = jax.jit(lambda p, x, m: jax.vmap(one, in_axes=(0, None, None))(p, x, m).mean(axis=0))
        else:
            self._apply = jax.jit(one)

    def probabilities(self, features: np.ndarray) -> np.ndarray:
        """(B, E, 21, 15, 15) features -> (B, labels) probabilities."""
        return np.asarray(self._apply(self.params, jnp.asarray(features), jnp.ones(features.shape[:2])))

    def for_pairs(self, pairs: Sequence[tuple[Scene, Scene]]) -> dict[str, np.ndarray]:
        """{function: probabilities over its argument domain} for one concept's pairs."""
        p = self.probabilities(pair_features(pairs)[None])[0]
        return {f: np.array([p[LABELS.index((f, v))] for v in arg_domain(f)]) for f in PREDICTED}


def argument_logp(probs: dict[str, np.ndarray], threshold: float = THRESHOLD) -> dict[str, np.ndarray]:
    """log p(argument | function) for the search: proportional to the predicted
    probability over the arguments that pass `threshold`, -inf elsewhere (all -inf: left out)."""
    out = {}
    for f, p in probs.items():
        keep = p >= threshold
        lp = np.full(len(p), -np.inf)
        if keep.any():
            lp[keep] = np.log(p[keep] / p[keep].sum())
        out[f] = lp
    return out


@functools.lru_cache(maxsize=1)
def default_predictor() -> Predictor:
    return Predictor()


def passing(probs: dict[str, np.ndarray], threshold: float = THRESHOLD) -> dict[str, list[str]]:
    return {f: [v for v, q in zip(arg_domain(f), p) if q >= threshold] for f, p in probs.items()}

