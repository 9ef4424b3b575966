"""A tiny built training-data folder shared by the argpred tests."""

from __future__ import annotations

import json

import numpy as np
import pytest

from argpred import data as argdata


@pytest.fixture(scope="session")
def tiny(tmp_path_factory):
    folder = tmp_path_factory.mktemp("argdata")
    arrays = argdata.build_shard(seed=5, shard=0, size=24)
    np.savez_compressed(folder / "shard0000.npz", **arrays)
    manifest = {"format": argdata.FORMAT, "version": argdata.VERSION, "seed": 5, "shard": 24,
                "labels": [list(x) for x in argdata.LABELS], "max_objects": 8,
                "shards": {"shard0000.npz": argdata._sha(folder / "shard0000.npz")}}
    (folder / "manifest.json").write_text(json.dumps(manifest))
    return folder
