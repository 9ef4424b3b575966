"""The question `vcc learn` puts back, drawn: the query input, then what each rival
program would make of it, side by side and labelled A, B, ..., so the user can say which
output they mean (or draw another)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from vccjax.machine.scene import Scene
from vccjax.views.viewer import FONT, GREY, INK, fit_text, put_text
from vccjax.vision.render import render

HEAD = 40


def query_sheet(scene: Scene, outputs: Sequence[tuple[str, str, Scene | None]], size: int = 256) -> np.ndarray:
    """RGB image: the input, then each (label, program text, output or None = fails)."""
    panels = [("input", "the new scene: which output do you mean?", scene)] + list(outputs)
    out = np.full((size + HEAD + 8, len(panels) * (size + 8), 3), 245, np.uint8)
    for k, (label, text, s) in enumerate(panels):
        x0 = k * (size + 8) + 4
        if s is None:
            img = np.full((size, size, 3), 200, np.uint8)
            cv2.putText(img, "fails here", (size // 2 - 52, size // 2), FONT, 0.6, INK, 1, cv2.LINE_AA)
        else:
            img = render(s, size)
        out[HEAD + 4:HEAD + 4 + size, x0:x0 + size] = img
        put_text(out, label, (x0 + 2, 16), INK, 0.5)
        put_text(out, fit_text(text, size - 4, 0.38), (x0 + 2, 34), GREY, 0.38)
    return out


def write_query(path: str | Path, scene: Scene, outputs: Sequence[tuple[str, str, Scene | None]],
                size: int = 256) -> Path:
    from vccjax import files

    path = Path(path)
    with files.whole(path) as tmp:
        if not cv2.imwrite(str(tmp), cv2.cvtColor(query_sheet(scene, outputs, size), cv2.COLOR_RGB2BGR)):
            raise OSError(f"{path}: could not be written")
    return path
