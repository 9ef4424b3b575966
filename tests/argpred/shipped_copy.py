"""A copy of the shipped weights to corrupt or re-record, for the tests that must not
touch the shipped files."""

from __future__ import annotations

import json


def copy_shipped(folder, keep_recall: bool = True):
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
