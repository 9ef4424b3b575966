"""A region's shape, by analysis by synthesis: the shape whose ideal drawing, placed by
the region's box and the shape's geometry (docs/vcc.md section 1), overlaps it best
(robust down to objects ten pixels wide), with a hollow region read as a star; and a
region that no one shape fits cut in two, for two objects of one colour that touch.
"""

from __future__ import annotations

import cv2
import numpy as np

from vccjax.machine.geometry import shape_polygon
from vccjax.machine.instructions import SHAPES

# A star fills about 0.6 of its convex hull, the other shapes over 0.9 however drawn
# (measured on the drawn styles of `vccjax.vision.drawings`, 10 to 100 pixels wide): a
# region under the first bound is a star; under the second, one whose overlap with a
# star is within the slack of the best overlap.
STAR_SOLIDITY = (0.8, 0.88)
STAR_IOU_SLACK = 0.2
# Two touching objects of one colour make one region that no one shape fits: a region
# no smaller than SPLIT_MIN_PX that fits worse than SPLIT_BELOW (a single object fits at
# 0.65 or better, tiny blurred ones included) or whose box is longer than SPLIT_ASPECT
# times its width (every shape's box is about square) is cut along the straight line
# that leaves two parts each fitting at least SPLIT_PART_FIT, if that gains SPLIT_GAIN.
SPLIT_BELOW, SPLIT_ASPECT, SPLIT_MIN_PX, SPLIT_PART_FIT, SPLIT_GAIN = 0.75, 1.3, 200, 0.75, 0.1

# A fringe joined to a region (texture specks, a shadowed side face) is at most this
# thick: FRINGE_PX pixels, or FRINGE_SHARE of the region's side on large regions.
FRINGE_PX, FRINGE_SHARE = 3, 0.1

Fit = tuple[str, float, float, float]  # shape, centre x, centre y, width (image pixels)


def box_to_object(shape: str, x0: float, y0: float, w: float, h: float) -> tuple[float, float, float]:
    """Centre and width (image pixels) that give a shape this bounding box (spec geometry)."""
    cx, cy = x0 + w / 2, y0 + h / 2
    if shape == "star":  # box: width 2R sin72, from R above the centre to R cos36 below it
        width = w / np.sin(np.radians(72))
        return cx, cy + (width / 2) * (1 - np.cos(np.radians(36))) / 2, width
    return cx, cy, max(w, h)


def _template(shape: str, cx: float, cy: float, width: float, x0: int, y0: int, w: int, h: int) -> np.ndarray:
    """The shape's pixels (coverage >= 1/2) in the window [x0, x0 + w) x [y0, y0 + h)."""
    ss = 4
    canvas = np.zeros((h * ss, w * ss), np.uint8)
    lx, ly = (cx - x0) * ss - 0.5, (cy - y0) * ss - 0.5
    if shape == "circle":
        cv2.circle(canvas, (int(round(lx * 16)), int(round(ly * 16))), int(round(width / 2 * ss * 16)),
                   255, -1, cv2.LINE_8, 4)
    else:
        poly = shape_polygon(shape, 0.0, 0.0, width * ss, 1.0) + (lx, ly)
        cv2.fillPoly(canvas, [np.round(poly * 16).astype(np.int32)], 255, cv2.LINE_8, 4)
    cover = cv2.resize(canvas, (w, h), interpolation=cv2.INTER_AREA)
    return cover >= 128


def _solidity(region: np.ndarray) -> float:
    """Pixels over the convex hull's area (half its perimeter added: a pixel count covers
    the boundary pixels the hull's polygon cuts in half)."""
    contours, _ = cv2.findContours(region.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    hull = cv2.convexHull(max(contours, key=cv2.contourArea))
    return float(region.sum()) / max(cv2.contourArea(hull) + cv2.arcLength(hull, True) / 2, 1.0)


def fit_one(region: np.ndarray, x0: int, y0: int, fringe: bool = True) -> tuple[float, Fit]:
    """(intersection over union, fit) of the best-fitting shape for a region cropped to its
    box at (x0, y0): the ideal rendering that overlaps it best. A region that fills little of its
    convex hull is a star even when blurred or outlined points make another shape overlap
    it better (`STAR_SOLIDITY`); a little-filled one whose overlap with a star is close
    to the best is one too (a stray pixel at a corner can thin a triangle's fill).
    `fringe`: also place the shapes by the box of a solid region's body (`_boxes`)."""
    h, w = region.shape
    solidity = _solidity(region)
    pad = 2
    win = np.zeros((h + 2 * pad, w + 2 * pad), bool)
    win[pad : pad + h, pad : pad + w] = region
    fits: dict[str, tuple[float, Fit]] = {}
    for bx, by, bw, bh in (_boxes(region) if fringe and solidity >= STAR_SOLIDITY[0] else [(0, 0, w, h)]):
        for shape in SHAPES:
            for grow in (-0.5, 0.0, 0.5, 1.0):
                cx, cy, width = box_to_object(shape, pad + bx - grow / 2, pad + by - grow / 2, bw + grow, bh + grow)
                t = _template(shape, cx, cy, width, 0, 0, w + 2 * pad, h + 2 * pad)
                iou = (t & win).sum() / max((t | win).sum(), 1)
                if iou > fits.get(shape, (-1.0,))[0]:
                    fits[shape] = (iou, (shape, cx - pad + x0, cy - pad + y0, width))
    best = max(fits.values(), key=lambda f: f[0])
    if solidity < STAR_SOLIDITY[0] or (solidity < STAR_SOLIDITY[1] and fits["star"][0] >= best[0] - STAR_IOU_SLACK):
        return fits["star"]
    return best


def _boxes(region: np.ndarray) -> list[tuple[int, int, int, int]]:
    """Where to place the ideal shapes (x, y, width, height in the region's crop): its box,
    and the box of its body without fringes a pixel or two thick (texture specks or a
    side face in shadow joined to one edge widen the box, and a square placed by a box
    wider than it is overlaps worse than a circle). The overlap is judged on the whole
    region either way. Used on solid regions only, and not on the halves of a region
    being cut in two: a star's points or a half's ragged cut are no fringe."""
    h, w = region.shape
    boxes = [(0, 0, w, h)]
    body = cv2.morphologyEx(region.astype(np.uint8), cv2.MORPH_OPEN, np.ones((5, 5), np.uint8)) > 0
    if body.any():
        ys, xs = np.nonzero(_largest(body))
        inner = (int(xs.min()), int(ys.min()), int(xs.max() - xs.min() + 1), int(ys.max() - ys.min() + 1))
        cut = (inner[0], inner[1], w - inner[0] - inner[2], h - inner[1] - inner[3])  # left, top, right, bottom
        if inner != boxes[0] and max(cut) <= max(FRINGE_PX, FRINGE_SHARE * max(w, h)):
            boxes.append(inner)  # a fringe, not a star's points (the opening cuts those back further)
    return boxes


def fit_shapes(region: np.ndarray, x0: int, y0: int) -> list[Fit]:
    """The object a region is, or the two it is when no one shape fits it and a straight
    cut leaves two parts that each fit one well (two touching objects of one colour)."""
    iou, fit = fit_one(region, x0, y0)
    h, w = region.shape
    if (iou >= SPLIT_BELOW and max(h, w) <= SPLIT_ASPECT * min(h, w)) or region.sum() < SPLIT_MIN_PX:
        return [fit]
    best, best_score = None, iou + SPLIT_GAIN
    ys, xs = np.nonzero(region)
    for angle in np.radians([0, 45, 90, 135]):
        along = xs * np.cos(angle) + ys * np.sin(angle)
        for q in np.linspace(0.15, 0.85, 29):
            side = along <= np.quantile(along, q)
            parts = []
            for keep in (side, ~side):
                part = np.zeros(region.shape, bool)
                part[ys[keep], xs[keep]] = True
                part = _largest(part)
                py, px = np.nonzero(part)
                parts.append((part.sum(), fit_one(part[py.min():py.max() + 1, px.min():px.max() + 1],
                                                  x0 + px.min(), y0 + py.min(), fringe=False)))
            if min(f[0] for _, f in parts) < SPLIT_PART_FIT:
                continue
            score = sum(n * f[0] for n, f in parts) / sum(n for n, _ in parts)
            if score > best_score:
                best, best_score = [f[1] for _, f in parts], score
    return best or [fit]


def _largest(mask: np.ndarray) -> np.ndarray:
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=8)
    if n <= 2:
        return mask
    return labels == 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))


