"""A small object's shape from its grey levels: analysis by synthesis with the blur.

Below about 40 pixels across, blur and JPEG eat a star's points and a square's
corners, and the region that a threshold cuts out is the wrong shape (a star's body
reads as a circle or a diamond). Blur moves darkness about but keeps all of it, so the
grey levels still say what was drawn: each shape is drawn ideally (its pixel coverage),
blurred, and compared with the picture's darkness around the object by normalised
correlation; centre, width and blur are fitted per shape, and the shape that explains
the picture best wins (docs/learn.md, "Pictures").
"""

from __future__ import annotations

import cv2
import numpy as np

from vccjax.machine.geometry import shape_polygon
from vccjax.machine.instructions import SHAPES

GREY_FIT_MAX_PX = 40  # objects up to this wide (pixels) are judged on grey levels too
_SS = 4  # supersampling of the ideal drawing
_SIGMAS = (0.5, 1.0, 1.6, 2.4)  # blur (pixels) the fit starts from
_GROWTH = (0.9, 1.0, 1.15, 1.3, 1.5)  # width over the region's, to start from


def coverage(shape: str, cx: float, cy: float, width: float, w: int, h: int) -> np.ndarray:
    """The share of each pixel of a w x h window that the ideal shape covers (centre in
    window pixels, pixel centres at half-integers' offsets as OpenCV draws)."""
    canvas = np.zeros((h * _SS, w * _SS), np.uint8)
    lx, ly = cx * _SS - 0.5, cy * _SS - 0.5
    if shape == "circle":
        cv2.circle(canvas, (int(round(lx * 16)), int(round(ly * 16))), max(1, int(round(width / 2 * _SS * 16))),
                   255, -1, cv2.LINE_8, 4)
    else:
        poly = shape_polygon(shape, 0.0, 0.0, width * _SS, 1.0) + (lx, ly)
        cv2.fillPoly(canvas, [np.round(poly * 16).astype(np.int32)], 255, cv2.LINE_8, 4)
    return cv2.resize(canvas, (w, h), interpolation=cv2.INTER_AREA).astype(np.float32) / 255.0


def _score(signal: np.ndarray, weight: np.ndarray, model: np.ndarray) -> float:
    """Weighted normalised correlation of the picture's darkness with a drawing."""
    sw = weight.sum()
    ms, mm = (weight * signal).sum() / sw, (weight * model).sum() / sw
    ds, dm = signal - ms, model - mm
    den = np.sqrt((weight * ds * ds).sum() * (weight * dm * dm).sum())
    return float((weight * ds * dm).sum() / den) if den > 0 else -1.0


def _fit_shape(shape: str, signal: np.ndarray, weight: np.ndarray, start: tuple[float, float, float]
               ) -> tuple[float, tuple[float, float, float]]:
    """(correlation, (cx, cy, width)) of one shape, fitted by pattern search from `start`."""
    h, w = signal.shape
    drawn: dict[tuple[float, float, float], np.ndarray] = {}  # the blur moves without redrawing

    def score(p: tuple[float, float, float, float]) -> float:
        cx, cy, width, sigma = p
        if not low <= width <= high or sigma < 0.3:
            return -2.0
        if p[:3] not in drawn:
            drawn[p[:3]] = coverage(shape, cx, cy, width, w, h)
        return _score(signal, weight, cv2.GaussianBlur(drawn[p[:3]], (0, 0), sigma))

    cx, cy, width = start
    low, high = 0.7 * width, 2.0 * width  # the region lost at most points and corners to blur
    best = max(((cx, cy, width * f, s) for f in _GROWTH for s in _SIGMAS), key=score)
    best_s = score(best)
    for step in (1.0, 0.5, 0.25):
        moved = True
        while moved:
            moved = False
            for k in range(4):
                for sign in (-1, 1):
                    p = list(best)
                    p[k] += sign * step * (0.5 if k == 3 else 1.0)
                    s = score(tuple(p))
                    if s > best_s + 1e-6:
                        best, best_s, moved = tuple(p), s, True
    return best_s, best[:3]


def grey_fit(darkness: np.ndarray, usable: np.ndarray, box: tuple[int, int, int, int]
             ) -> tuple[str, float, float, float, float, float]:
    """(shape, centre x, centre y, width, its correlation, the runner-up's) of the object
    whose region has the box (x0, y0, x1, y1), from `darkness` (0 at the table, 1 at the
    object's body) where `usable` (pixels of no other object)."""
    from vccjax.vision.shape_fit import box_to_object

    x0, y0, x1, y1 = box
    side = max(x1 - x0, y1 - y0)
    pad = int(np.ceil(0.3 * side + 3 * _SIGMAS[-1])) + 1
    H, W = darkness.shape
    wx0, wy0, wx1, wy1 = max(x0 - pad, 0), max(y0 - pad, 0), min(x1 + pad, W), min(y1 + pad, H)
    signal = darkness[wy0:wy1, wx0:wx1].astype(np.float32)
    weight = usable[wy0:wy1, wx0:wx1].astype(np.float32)
    results = []
    for shape in SHAPES:
        cx, cy, width = box_to_object(shape, x0 - wx0, y0 - wy0, x1 - x0, y1 - y0)
        s, (cx, cy, width) = _fit_shape(shape, signal, weight, (cx, cy, width))
        results.append((s, shape, cx + wx0, cy + wy0, width))
    results.sort(reverse=True)
    s, shape, cx, cy, width = results[0]
    return shape, cx, cy, width, s, results[1][0]
