"""`scene_parse` from pixels: an RGB image to a Scene, with OpenCV.

Objects are the saturated regions (table, pointer and outlines are not saturated).
Each colour class is segmented on its own hue band, so that touching objects of
different colours stay apart. A region's shape is the one whose ideal rendering, placed
by the region's box and the shape's geometry (docs/vcc.md section 1), overlaps it best
(analysis by synthesis; robust down to objects ten pixels wide). The pointer is a dark ring, away from any
object. An image with no objects, or with an object of a colour outside the four,
raises SceneError naming what was found and where.
"""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.errors import SceneError
from vccjax.machine.instructions import SHAPES
from vccjax.machine.geometry import shape_polygon
from vccjax.machine.scene import Scene, SceneObject, to_units

# OpenCV hue (0..180) bands of the four colours; anything saturated outside them is unknown.
HUE_BANDS = {"red": ((0, 10), (165, 180)), "yellow": ((18, 38),), "green": ((45, 88),), "blue": ((95, 135),)}


@dataclasses.dataclass(frozen=True)
class ParseOptions:
    min_saturation: int = 90
    min_value: int = 60
    min_area_px: int = 12  # regions smaller than this are noise
    edge_saturation: int = 40  # a region grows into connected pixels of its hue down to this (blurred edges)
    outline_value: int = 90  # darker pixels hugging a region are its outline, part of the object
    outline_width: float = 0.008  # of the image's side: how far an outline may reach out


def _hue_mask(hsv: np.ndarray, bands) -> np.ndarray:
    h = hsv[..., 0]
    m = np.zeros(h.shape, bool)
    for lo, hi in bands:
        m |= (h >= lo) & (h <= hi)
    return m


def _box_to_object(shape: str, x0: float, y0: float, w: float, h: float) -> tuple[float, float, float]:
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


def _classify(region: np.ndarray, x0: int, y0: int) -> tuple[str, float, float, float]:
    """Best-fitting shape by intersection over union with its ideal rendering (analysis by
    synthesis), with centre and width in image pixels."""
    h, w = region.shape
    pad = 2
    win = np.zeros((h + 2 * pad, w + 2 * pad), bool)
    win[pad : pad + h, pad : pad + w] = region
    best = ("square", 0.0, 0.0, 0.0)
    best_iou = -1.0
    for shape in SHAPES:
        for grow in (-0.5, 0.0, 0.5, 1.0):
            cx, cy, width = _box_to_object(shape, pad - grow / 2, pad - grow / 2, w + grow, h + grow)
            t = _template(shape, cx, cy, width, 0, 0, w + 2 * pad, h + 2 * pad)
            iou = (t & win).sum() / max((t | win).sum(), 1)
            if iou > best_iou:
                best_iou, best = iou, (shape, cx - pad + x0, cy - pad + y0, width)
    return best


def parse_image(image: np.ndarray, options: ParseOptions = ParseOptions()) -> Scene:
    """An RGB uint8 image (H, W, 3) of a tabletop scene to a Scene."""
    if not isinstance(image, np.ndarray) or image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise SceneError(f"expected an RGB uint8 image (H, W, 3), got {getattr(image, 'shape', type(image))}")
    size_y, size_x = image.shape[:2]
    if size_x != size_y:
        raise SceneError(f"the image is {size_x} x {size_y} pixels; the workspace is square: crop the picture "
                         "to the workspace (or pad it) so it is square")
    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    saturated = (hsv[..., 1] >= options.min_saturation) & (hsv[..., 2] >= options.min_value)
    faint = (hsv[..., 1] >= options.edge_saturation) & (hsv[..., 2] >= options.min_value // 2)
    dark = hsv[..., 2] < options.outline_value
    reach = max(1, int(round(options.outline_width * size_x)))
    objects: list[SceneObject] = []
    claimed = np.zeros(saturated.shape, bool)
    for color, bands in HUE_BANDS.items():
        # no morphological opening here: OpenCV's erode/dilate with an even kernel shift the
        # region by a pixel, and tiny specks are dropped by area below anyway
        hue = _hue_mask(hsv, bands)
        strong = (saturated & hue).astype(np.uint8)
        n, labels, stats, _ = cv2.connectedComponentsWithStats(strong, connectivity=8)
        for k in range(1, n):
            x0, y0, w, h, area = stats[k]
            if area < options.min_area_px or claimed[labels == k].any():
                continue  # noise, or a core already taken into a region grown from another
            region = _grown(labels == k, faint & hue, dark, reach)
            ys, xs = np.nonzero(region)
            x0, y0, x1, y1 = xs.min(), ys.min(), xs.max() + 1, ys.max() + 1
            claimed |= region
            shape, cx, cy, width = _classify(region[y0:y1, x0:x1], x0, y0)
            objects.append(SceneObject(shape, color, cx / size_x, cy / size_y, width / size_x))
    leftover = saturated & ~claimed
    leftover = cv2.morphologyEx(leftover.astype(np.uint8), cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
    n, _, stats, cents = cv2.connectedComponentsWithStats(leftover, connectivity=8)
    for k in range(1, n):
        if stats[k][4] >= 4 * options.min_area_px:
            hue = int(np.median(hsv[..., 0][_labels_eq(leftover, stats[k])]))
            x, y = cents[k][0] / size_x, cents[k][1] / size_y
            raise SceneError(f"object at ({x:.2f}, {y:.2f}) has an unknown color (hue {2 * hue} degrees)")
    if not objects:
        raise SceneError("no objects found in the image")
    objects.sort(key=lambda o: (o.y, o.x))  # a stable, image-independent order
    return Scene(tuple(_clamp(o) for o in objects), _find_pointer(hsv, claimed))


def _grown(seed: np.ndarray, faint: np.ndarray, dark: np.ndarray, reach: int) -> np.ndarray:
    """A region grown from its saturated core into the connected faint pixels of its hue
    (edges and thin star points that blur and JPEG desaturate), then into the dark pixels
    hugging it within `reach` (an outline drawn around the shape)."""
    ys, xs = np.nonzero(seed)
    pad = 2 * reach + 2
    y0, x0 = max(ys.min() - pad, 0), max(xs.min() - pad, 0)
    y1, x1 = min(ys.max() + pad + 1, seed.shape[0]), min(xs.max() + pad + 1, seed.shape[1])
    core = seed[y0:y1, x0:x1]
    n, labels = cv2.connectedComponents((faint[y0:y1, x0:x1] | core).astype(np.uint8), connectivity=8)
    keep = np.unique(labels[core])
    region = np.isin(labels, keep[keep > 0]) | core
    ring = cv2.dilate(region.astype(np.uint8), np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)) > 0
    region |= ring & dark[y0:y1, x0:x1]
    out = np.zeros(seed.shape, bool)
    out[y0:y1, x0:x1] = region
    return out


def _labels_eq(mask: np.ndarray, stat) -> np.ndarray:
    x0, y0, w, h, _ = stat
    out = np.zeros(mask.shape, bool)
    out[y0 : y0 + h, x0 : x0 + w] = mask[y0 : y0 + h, x0 : x0 + w] > 0
    return out


def _clamp(o: SceneObject) -> SceneObject:
    """Keep an estimated box inside the workspace (estimates near an edge can overshoot)."""
    u = DEFAULT_CONFIG.units  # clamp in the machine's integer units, as Scene.validate tests
    w = to_units(o.width, DEFAULT_CONFIG)
    lo, hi = -(-w // 2), (2 * u - w) // 2

    def inside(v: float) -> float:
        return min(max(to_units(v, DEFAULT_CONFIG), lo), hi) / u

    return dataclasses.replace(o, x=inside(o.x), y=inside(o.y))


def _find_pointer(hsv: np.ndarray, objects: np.ndarray) -> tuple[float, float] | None:
    """The pointer: a dark ring with a light centre, away from objects."""
    size_y, size_x = hsv.shape[:2]
    # dark by value alone: near black, sensor noise makes any hue and saturation
    dark = (hsv[..., 2] < 80).astype(np.uint8)
    dark = cv2.morphologyEx(dark, cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8))
    near = cv2.dilate(objects.astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
    dark[near] = 0  # outlines hug objects; the pointer does not
    n, _, stats, cents = cv2.connectedComponentsWithStats(dark, connectivity=8)
    best, best_area = None, 0
    expect = (0.036 * size_x) ** 2  # the ring's box
    for k in range(1, n):
        x0, y0, w, h, area = stats[k]
        if 0.3 * expect <= w * h <= 3 * expect and 0.6 <= w / max(h, 1) <= 1.6 and area > best_area:
            best, best_area = ((x0 + w / 2) / size_x, (y0 + h / 2) / size_y), area
    return best
