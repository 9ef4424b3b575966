"""`scene_parse` from pixels: an RGB image to a Scene, with OpenCV.

Objects are the saturated regions (table, pointer and outlines are not saturated).
Each colour class is segmented on its own hue band, so that touching objects of
different colours stay apart; a region's shape is fitted by `vccjax.vision.shape_fit`.
The pointer is a dark ring round a light centre, on an object or not. An image with no
objects, or with an object of a colour outside the four, raises SceneError naming what
was found and where. docs/learn.md ("Pictures") says what each step is for.
"""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.errors import SceneError
from vccjax.machine.scene import Scene, SceneObject, to_units
from vccjax.vision.grey_fit import GREY_FIT_MAX_PX, grey_fit
from vccjax.vision.shape_fit import fit_shapes

DARK_TABLE = 120  # a table whose median brightness (HSV value) is below this is dark (the arm camera's, dimmed: 160)
DARK_TABLE_LIFT = 30  # on a dark table, colour counts this much brighter than the table
# OpenCV hue (0..180) bands of the four colours; anything saturated outside them is unknown.
HUE_BANDS = {"red": ((0, 10), (165, 180)), "yellow": ((18, 38),), "green": ((45, 88),), "blue": ((95, 135),)}


@dataclasses.dataclass(frozen=True)
class ParseOptions:
    min_saturation: int = 90
    min_value: int = 60
    min_area_px: int = 12  # regions smaller than this are noise
    min_core_px: int = 4  # a core this small counts if its region (outline and all) is not too small
    edge_saturation: int = 40  # a region grows into connected pixels of its hue down to this (blurred edges)
    outline_value: int = 90  # darker pixels hugging a region are its outline, part of the object
    outline_width: float = 0.008  # of the image's side: how far an outline may reach out
    grey_fit: bool = True  # judge small objects' shapes on grey levels too (`vccjax.vision.grey_fit`)


def _hue_mask(hsv: np.ndarray, bands) -> np.ndarray:
    h = hsv[..., 0]
    m = np.zeros(h.shape, bool)
    for lo, hi in bands:
        m |= (h >= lo) & (h <= hi)
    return m


def parse_image(image: np.ndarray, options: ParseOptions = ParseOptions()) -> Scene:
    """An RGB uint8 image (H, W, 3) of a tabletop scene to a Scene."""
    if not isinstance(image, np.ndarray) or image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise SceneError(f"expected an RGB uint8 image (H, W, 3), got {getattr(image, 'shape', type(image))}")
    size_y, size_x = image.shape[:2]
    if size_x != size_y:
        raise SceneError(f"the image is {size_x} x {size_y} pixels; the workspace is square: crop the picture "
                         "to the workspace (or pad it) so it is square")
    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    luma = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
    saturated = (hsv[..., 1] >= options.min_saturation) & (hsv[..., 2] >= options.min_value)
    faint = (hsv[..., 1] >= options.edge_saturation) & (hsv[..., 2] >= options.min_value // 2)
    table = float(np.median(hsv[..., 2][~saturated])) if (~saturated).any() else 255.0
    dark_table = table < DARK_TABLE
    if dark_table:
        # a dark desk, a slide's dark theme: a tinted dark table is faintly saturated
        # itself, so colour counts only where it is brighter than the table; no outline
        # can be told from the table, and no dark ring away from objects is a pointer
        lit = hsv[..., 2] >= table + DARK_TABLE_LIFT
        saturated, faint = saturated & lit, faint & lit
    dark = (hsv[..., 2] < options.outline_value) & ~dark_table
    reach = max(1, int(round(options.outline_width * size_x)))
    ring = _pointer_ring(hsv)
    under_pointer = np.zeros(dark.shape, bool)
    if ring is not None:  # its black ring is no object's outline
        cv2.circle(under_pointer.view(np.uint8), (int(round(ring[0])), int(round(ring[1]))),
                   int(np.ceil(ring[2])) + 1, 1, -1)
        dark = dark & ~under_pointer
    # each pixel's nearest saturated region (the pointer's disc joining what it cuts):
    # outlines and blurred edges between two objects that touch are split between them,
    # not grown into by both
    _, owner = cv2.distanceTransformWithLabels((~(saturated | under_pointer)).astype(np.uint8), cv2.DIST_L2, 5,
                                               labelType=cv2.DIST_LABEL_CCOMP)
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
            if area < options.min_core_px or claimed[labels == k].any():
                continue  # noise, or a core already taken into a region grown from another
            mine = owner == np.bincount(owner[labels == k]).argmax()
            # the pointer's ring may cut an object in two: its disc joins the pieces
            grown = _grown(labels == k, (faint & hue & mine) | under_pointer, dark & mine, reach)
            region = _under_pointer(grown, under_pointer)
            if region.sum() < options.min_area_px:
                continue  # a speck (a small star's fill inside its outline is little more than its core)
            claimed |= grown
            # the shape is judged on the half-saturation contour (the faint skirt fills a
            # star's notches and rounds corners), outlines kept, then on brightness
            half = hsv[..., 1] >= 0.5 * np.median(hsv[..., 1][labels == k])
            shaped = _luma_points(region & (half | dark), labels == k, luma, ~mine | (saturated & ~hue), reach,
                                  dark_table)
            ys, xs = np.nonzero(shaped)
            x0, y0, x1, y1 = xs.min(), ys.min(), xs.max() + 1, ys.max() + 1
            fits = fit_shapes(shaped[y0:y1, x0:x1], x0, y0)
            if options.grey_fit and len(fits) == 1 and max(x1 - x0, y1 - y0) <= GREY_FIT_MAX_PX:
                fits = [_grey_refit(fits[0], luma, labels == k, mine & ~(saturated & ~hue) & ~under_pointer,
                                    (x0, y0, x1, y1), reach, dark_table)]
            for shape, cx, cy, width in fits:
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
    pointer = (ring[0] / size_x, ring[1] / size_y) if ring is not None else \
        None if dark_table else _find_pointer(hsv, claimed)
    return Scene(tuple(_clamp(o) for o in objects), pointer)


def _pointer_ring(hsv: np.ndarray) -> tuple[float, float, float] | None:
    """(x, y, outer radius) in pixels of the pointer drawn as a dark ring round a light
    centre, wherever it lies (on an object too), or None: a small light spot, enclosed
    (not part of the table around it), most of a ring around it dark."""
    size = hsv.shape[1]
    light = ((hsv[..., 2] >= 150) & (hsv[..., 1] <= 90)).astype(np.uint8)
    n, _, stats, cents = cv2.connectedComponentsWithStats(light, connectivity=4)
    hole = np.pi * (0.0085 * size) ** 2  # the light centre's expected area
    best, best_dark = None, 0.6
    angles = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    for k in range(1, n):
        x0, y0, w, h, area = stats[k]
        if not 0.2 * hole <= area <= 4 * hole or not 0.5 <= w / h <= 2 or x0 == 0 or y0 == 0 \
                or x0 + w == size or y0 + h == hsv.shape[0]:
            continue
        cx, cy = cents[k]
        r = max(np.sqrt(area / np.pi), 0.9 * np.sqrt(hole / np.pi))  # blur shrinks a small light centre
        dark = 0
        for f in (1.35, 1.7):  # the ring: between the centre's rim and the pointer's (2 to 2.2 radii)
            xs = np.clip(np.round(cx + f * r * np.cos(angles)).astype(int), 0, size - 1)
            ys = np.clip(np.round(cy + f * r * np.sin(angles)).astype(int), 0, hsv.shape[0] - 1)
            dark += int((hsv[ys, xs, 2] < 100).sum())
        share = dark / (2 * len(angles))
        if share > best_dark:
            best, best_dark = (float(cx), float(cy), 2.2 * r), share
    return best


def _under_pointer(region: np.ndarray, pointer: np.ndarray) -> np.ndarray:
    """A region with the part the pointer hides given back: the pointer's disc where it
    lies within the region's convex hull (the ring cut a hole or a notch in it)."""
    seen = region & ~pointer
    if not pointer.any() or not seen.any() or \
            not (cv2.dilate(seen.astype(np.uint8), np.ones((3, 3), np.uint8)) & pointer).any():
        return seen if seen.any() else region
    ys, xs = np.nonzero(seen | pointer)
    y0, y1, x0, x1 = ys.min(), ys.max() + 1, xs.min(), xs.max() + 1
    contours, _ = cv2.findContours(seen[y0:y1, x0:x1].astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    hull = np.zeros((y1 - y0, x1 - x0), np.uint8)
    cv2.fillPoly(hull, [cv2.convexHull(np.concatenate(contours))], 1)
    out = seen.copy()
    out[y0:y1, x0:x1] |= (hull > 0) & pointer[y0:y1, x0:x1]
    return out


def _grown(seed: np.ndarray, faint: np.ndarray, dark: np.ndarray, reach: int) -> np.ndarray:
    """A region grown from its saturated core into the connected faint pixels of its hue
    (edges and thin star points that blur and JPEG desaturate), then into the dark pixels
    hugging it within `reach` (an outline drawn around the shape)."""
    _, labels = cv2.connectedComponents((faint | seed).astype(np.uint8), connectivity=8)
    keep = np.unique(labels[seed])
    grown = np.isin(labels, keep[keep > 0]) | seed
    ys, xs = np.nonzero(grown)
    steps = _point_reach(grown)
    pad = 2 * reach + 2 + steps
    y0, x0 = max(ys.min() - pad, 0), max(xs.min() - pad, 0)
    y1, x1 = min(ys.max() + pad + 1, seed.shape[0]), min(xs.max() + pad + 1, seed.shape[1])
    region = grown[y0:y1, x0:x1]
    ring = cv2.dilate(region.astype(np.uint8), np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)) > 0
    region = region | (ring & dark[y0:y1, x0:x1])
    # a thin star point can be all outline: follow the dark pixels connected to the region
    # (not across the light table) as far as a point reaches out from the body
    region = _follow(region, dark[y0:y1, x0:x1], steps)
    out = np.zeros(seed.shape, bool)
    out[y0:y1, x0:x1] = region
    return out


def _luma_points(shaped: np.ndarray, core: np.ndarray, luma: np.ndarray, others: np.ndarray,
                 reach: int, dark_table: bool = False) -> np.ndarray:
    """`shaped` grown into the connected pixels darker than the table around it (lighter, on
    a dark table) by 45% of the core's contrast (a little under half, so a small square's
    soft corners stay).
    JPEG keeps brightness at full resolution but colour at half, so a small star's
    blurred points still show in brightness when their colour is gone. Pixels nearer
    another region, or of another colour's object, are never taken."""
    ys, xs = np.nonzero(shaped)
    pad = 4 * reach + 4
    y0, x0 = max(ys.min() - pad, 0), max(xs.min() - pad, 0)
    y1, x1 = min(ys.max() + pad + 1, luma.shape[0]), min(xs.max() + pad + 1, luma.shape[1])
    near = cv2.dilate(shaped[y0:y1, x0:x1].astype(np.uint8), np.ones((2 * reach + 3,) * 2, np.uint8)) > 0
    table = luma[y0:y1, x0:x1][~near]
    if table.size == 0:
        return shaped
    bg, body = float(np.median(table)), float(np.median(luma[core]))
    if (body - bg if dark_table else bg - body) < 24:
        return shaped  # too little contrast in brightness to follow (a yellow object on a grey table)
    # as far from the table as 45% of the way to the body: darker on a light table,
    # lighter on a dark one
    ink = ((bg - luma[y0:y1, x0:x1]) / (bg - body) >= 0.45) & ~others[y0:y1, x0:x1]
    out = shaped.copy()
    start = shaped[y0:y1, x0:x1] & ink
    if not start.any():
        return shaped
    out[y0:y1, x0:x1] = _follow(start, ink, _point_reach(shaped))
    return out


def _grey_refit(fit: tuple, luma: np.ndarray, core: np.ndarray, usable: np.ndarray,
                box: tuple[int, int, int, int], reach: int, dark_table: bool = False) -> tuple:
    """A small object's shape, centre and width from its grey levels (`grey_fit`), in
    place of the region's fit; the region's fit stands where brightness says too little."""
    x0, y0, x1, y1 = box
    pad = max(x1 - x0, y1 - y0) + 4 * reach + 4  # wider than `grey_fit`'s own window
    ya, xa = max(y0 - pad, 0), max(x0 - pad, 0)
    yb, xb = min(y1 + pad, luma.shape[0]), min(x1 + pad, luma.shape[1])
    grey, free = luma[ya:yb, xa:xb].astype(np.float32), usable[ya:yb, xa:xb]
    around = free.copy()  # the table: the window less the object's box and its outline's reach
    r = 2 * reach + 2
    around[max(y0 - ya - r, 0):y1 - ya + r, max(x0 - xa - r, 0):x1 - xa + r] = False
    if around.sum() < 16:
        return fit
    bg, body = float(np.median(grey[around])), float(np.median(luma[core]))
    if (body - bg if dark_table else bg - body) < 24:
        return fit
    darkness = np.clip((bg - grey) / (bg - body), -0.5, 3.0)  # the object's share of each pixel, either contrast
    shape, cx, cy, width, _, _ = grey_fit(darkness, free, (x0 - xa, y0 - ya, x1 - xa, y1 - ya))
    return shape, cx + xa, cy + ya, width


def _point_reach(region: np.ndarray) -> int:
    """How far a star's point may reach out of what was found of it (pixels)."""
    ys, xs = np.nonzero(region)
    return int(0.35 * max(ys.max() - ys.min(), xs.max() - xs.min())) + 1


def _follow(region: np.ndarray, ink: np.ndarray, steps: int) -> np.ndarray:
    """`region` grown into the `ink` pixels connected to it, at most `steps` pixels out."""
    ink = (ink | region).astype(np.uint8)
    step = np.ones((3, 3), np.uint8)
    for _ in range(steps):
        more = (cv2.dilate(region.astype(np.uint8), step) & ink) > 0
        if (more == region).all():
            break
        region = more
    return region


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
