"""JSON files that carry the sha256 of their own content, written whole: the learned
library and the user's saved concepts. An edited file no longer matches its hash."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

FIELD = "content_sha256"


def content_sha256(content: dict) -> str:
    """The sha256 of `content` without its own hash field (canonical JSON)."""
    body = {k: v for k, v in content.items() if k != FIELD}
    return hashlib.sha256(json.dumps(body, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def seal(content: dict) -> dict:
    return {**content, FIELD: content_sha256(content)}


def intact(content: dict) -> bool:
    return content.get(FIELD) == content_sha256(content)


def write_whole(path: Path, content: dict) -> None:
    """Write JSON through a temporary file replaced at once: never half a file."""
    from vccjax import files

    files.write_json(path, content, sort_keys=True)
