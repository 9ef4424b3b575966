"""Fixtures the model, compression and chain tests share: the reference programs as op
lists and their compression (each built once per module that asks for it)."""

from __future__ import annotations

import pytest

from search.compress import compress
from vccjax.world.concepts import all_concepts


@pytest.fixture(scope="module")
def reference_ops() -> list[list[int]]:
    return [list(p.ops) for p in all_concepts().values()]


@pytest.fixture(scope="module")
def compressed(reference_ops):
    return compress(reference_ops, order=1, epsilon=0.1, cap=5)
