"""Scenes to RGB images, in two families of styles.

- schematic: flat background, flat saturated colours, as in the paper's figures;
- varied: seeded background (flat tint, gradient or texture), lighting gradient,
  per-object shading and colour jitter, dark outlines, noise and a slight blur.

Shapes are drawn from the same geometry as the machine's masks (docs/vcc.md section 1), at
the image's own resolution with 4x supersampling on the edges. The pointer is a
black-ringed white cross-hair dot. Imagined objects are never drawn.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from vccjax.machine.geometry import shape_polygon
from vccjax.machine.scene import Scene

# Flat RGB colours of the schematic style; perception classifies by hue.
PALETTE = {
    "red": (220, 40, 40),
    "green": (40, 170, 60),
    "blue": (40, 80, 220),
    "yellow": (235, 200, 30),
}
BACKGROUND = (255, 255, 255)
STYLES = ("schematic", "varied")
_SS = 4  # supersampling for anti-aliased edges


def _draw_shape(canvas: np.ndarray, shape: str, x: float, y: float, w: float, color, size: int,
                outline=None, thickness: int = 0, origin: tuple[int, int] = (0, 0)) -> None:
    """Draw on a supersampled canvas whose pixel (0, 0) is pixel `origin` of the full one."""
    px = size * _SS
    shift = 4  # cv2 sub-pixel coordinates (1/16 pixel); pixel i covers [i, i + 1) * 1/px
    ox, oy = origin
    if shape == "circle":
        centre = (int(round((x * px - 0.5 - ox) * 16)), int(round((y * px - 0.5 - oy) * 16)))
        radius = int(round(w / 2 * px * 16))
        cv2.circle(canvas, centre, radius, color, -1, cv2.LINE_AA, shift)
        if outline is not None:
            cv2.circle(canvas, centre, radius, outline, thickness * _SS, cv2.LINE_AA, shift)
        return
    poly = np.round((shape_polygon(shape, x, y, w, px) - 0.5 - (ox, oy)) * 16).astype(np.int32)
    cv2.fillPoly(canvas, [poly], color, cv2.LINE_AA, shift)
    if outline is not None:
        cv2.polylines(canvas, [poly], True, outline, thickness * _SS, cv2.LINE_AA, shift)


def _draw_pointer(canvas: np.ndarray, p: tuple[float, float], size: int) -> None:
    px = size * _SS
    c = (int(round((p[0] * px - 0.5) * 16)), int(round((p[1] * px - 0.5) * 16)))
    r = int(round(0.018 * px * 16))
    cv2.circle(canvas, c, r, (0, 0, 0), -1, cv2.LINE_AA, 4)
    cv2.circle(canvas, c, r // 2, (255, 255, 255), -1, cv2.LINE_AA, 4)


def render(scene: Scene, size: int = 384, style: str = "schematic", seed: int = 0) -> np.ndarray:
    """An (size, size, 3) uint8 RGB image of the scene."""
    if style not in STYLES:
        raise ValueError(f"unknown style {style!r}; expected one of {STYLES}")
    if size < 64:
        raise ValueError(f"image size must be at least 64, got {size}")
    big = size * _SS
    if style == "schematic":
        canvas = np.full((big, big, 3), BACKGROUND, np.uint8)
        for o in scene.objects:
            _draw_shape(canvas, o.shape, o.x, o.y, o.width, PALETTE[o.color], size)
        if scene.pointer is not None:
            _draw_pointer(canvas, scene.pointer, size)
        return cv2.resize(canvas, (size, size), interpolation=cv2.INTER_AREA)
    return _render_varied(scene, size, np.random.default_rng(seed))


def _background(rng: np.random.Generator, size: int) -> np.ndarray:
    yy, xx = np.mgrid[0:size, 0:size] / size
    base = rng.uniform(150, 245, 3)  # light, low-saturation table colours
    base = base.mean() + (base - base.mean()) * 0.3
    kind = rng.integers(3)
    img = np.broadcast_to(base, (size, size, 3)).astype(np.float64)
    if kind >= 1:  # a gradient across the table
        ang = rng.uniform(0, 2 * math.pi)
        g = (xx * math.cos(ang) + yy * math.sin(ang))
        img = img + (g - g.mean())[..., None] * rng.uniform(20, 50)
    if kind == 2:  # wood-like or fabric texture
        freq = rng.uniform(8, 30)
        tex = np.sin(2 * math.pi * (freq * yy + 3 * np.sin(2 * math.pi * xx * rng.uniform(1, 3))))
        img = img + tex[..., None] * rng.uniform(4, 12)
    return img


def _render_varied(scene: Scene, size: int, rng: np.random.Generator) -> np.ndarray:
    big = size * _SS
    img = cv2.resize(_background(rng, size), (big, big), interpolation=cv2.INTER_LINEAR)
    for o in scene.objects:
        base = np.array(PALETTE[o.color], np.float64)
        # colour jitter within the class: brightness and a little channel noise
        col = np.clip(base * rng.uniform(0.8, 1.1) + rng.normal(0, 8, 3), 0, 255)
        ang = rng.uniform(0, 2 * math.pi)
        outlined = rng.random() < 0.5
        # work in the object's window only
        r = int(math.ceil((o.width / 2) * big)) + 3 * _SS
        x0, y0 = max(int(o.x * big) - r, 0), max(int(o.y * big) - r, 0)
        x1, y1 = min(int(o.x * big) + r, big), min(int(o.y * big) + r, big)
        shape = (y1 - y0, x1 - x0)
        layer = np.zeros(shape + (3,), np.uint8)
        mask = np.zeros(shape, np.uint8)
        _draw_shape(layer, o.shape, o.x, o.y, o.width, tuple(float(v) for v in col), size, origin=(x0, y0))
        _draw_shape(mask, o.shape, o.x, o.y, o.width, 255, size, origin=(x0, y0))
        # shading: darker away from a light direction, within the object
        yy, xx = (np.mgrid[y0:y1, x0:x1] + 0.5) / big
        shade = 1 + 0.15 * ((xx - o.x) * math.cos(ang) + (yy - o.y) * math.sin(ang)) / max(o.width, 1e-3)
        a = (mask / 255.0)[..., None]
        win = img[y0:y1, x0:x1]
        win = win * (1 - a) + layer.astype(np.float64) * shade[..., None] * a
        if outlined:  # a dark outline
            edge = np.zeros(shape, np.uint8)
            _draw_shape(edge, o.shape, o.x, o.y, o.width, 0, size, outline=255, thickness=1, origin=(x0, y0))
            win = win * (1 - 0.6 * (edge / 255.0)[..., None])
        img[y0:y1, x0:x1] = win
    if scene.pointer is not None:
        ptr = np.clip(img, 0, 255).astype(np.uint8)
        _draw_pointer(ptr, scene.pointer, size)
        img = ptr.astype(np.float64)
    img = cv2.resize(img, (size, size), interpolation=cv2.INTER_AREA)
    # lighting gradient over the whole image, sensor noise, slight blur
    yy, xx = np.mgrid[0:size, 0:size] / size
    ang = rng.uniform(0, 2 * math.pi)
    light = 1 + rng.uniform(0.05, 0.15) * ((xx - 0.5) * math.cos(ang) + (yy - 0.5) * math.sin(ang))
    img = img * light[..., None] + rng.normal(0, rng.uniform(2, 6), img.shape)
    img = np.clip(img, 0, 255).astype(np.uint8)
    sigma = rng.uniform(0.3, 0.8)
    return cv2.GaussianBlur(img, (0, 0), sigma)


def render_pairs(pairs, style: str = "schematic", size: int = 384, seed: int = 0) -> list[tuple[np.ndarray, np.ndarray]]:
    """Example pairs as RGB images, seeded per pair (the same arguments give the same
    pixels; input and output of a pair share a style draw)."""
    out = []
    for k, (a, b) in enumerate(pairs):
        s = int(np.random.default_rng([seed, k]).integers(2**31))
        out.append((render(a, size, style, seed=s), render(b, size, style, seed=s)))
    return out
