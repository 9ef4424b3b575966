"""Scenes drawn as users draw them, to measure the image parser on pictures it was not
built against. Written apart from `render.py` (Pillow's drawing, its own colours and
pointer), so that a parser tuned to our renderer's quirks is caught out.

Styles:
- `outline`: flat fills with a black outline, as in a drawing program;
- `jitter`: hand-drawn: every vertex (and a circle's rim) moved by up to 2% of the width;
- `photo`: flat fills, then blur, sensor noise and JPEG compression;
- `shades`: other shades of the four colours on a tinted background;
- `dark`: flat fills on a dark table (near black to slate), as on a dark desk or a
  slide with a dark theme.
"""

from __future__ import annotations

import io
import math

import numpy as np

from vccjax.machine.geometry import shape_polygon
from vccjax.machine.scene import Scene

STYLES = ("outline", "jitter", "photo", "shades", "dark")

BASE = {"red": (214, 39, 40), "green": (44, 160, 44), "blue": (31, 119, 180), "yellow": (240, 200, 20)}
SHADES = {  # a few other shades a person might pick for each colour
    "red": [(200, 30, 60), (235, 60, 45), (170, 20, 30)],
    "green": [(60, 180, 90), (30, 130, 50), (110, 190, 60)],
    "blue": [(30, 60, 180), (70, 110, 240), (40, 90, 150)],
    "yellow": [(250, 220, 60), (225, 185, 15), (245, 205, 90)],
}


def _outline_points(shape: str, x: float, y: float, w: float, size: int, rng: np.random.Generator | None,
                    jitter: float) -> list[tuple[float, float]]:
    """The shape's outline in image pixels (a circle as a 48-gon), vertices moved by up to
    `jitter` x the width when `rng` is given."""
    if shape == "circle":
        t = np.linspace(0, 2 * math.pi, 48, endpoint=False)
        pts = np.stack([x * size + w / 2 * size * np.cos(t), y * size + w / 2 * size * np.sin(t)], 1)
    else:
        pts = shape_polygon(shape, x, y, w, size)
    if rng is not None:
        pts = pts + rng.uniform(-jitter, jitter, pts.shape) * w * size
    return [(float(a), float(b)) for a, b in pts]


def draw(scene: Scene, style: str, size: int = 256, seed: int = 0) -> np.ndarray:
    """An RGB uint8 picture of `scene` in one of `STYLES` (`size` pixels high)."""
    from PIL import Image, ImageDraw, ImageFilter

    if style not in STYLES:
        raise ValueError(f"unknown drawing style {style!r}; expected one of {', '.join(STYLES)}")
    rng = np.random.default_rng(seed)
    ss = 4  # Pillow draws without anti-aliasing: draw large, then shrink
    big = size * ss
    background = (255, 255, 255)
    if style == "shades":
        background = tuple(int(v) for v in rng.integers(228, 250, 3))
    elif style == "dark":
        grey = int(rng.integers(12, 60))
        background = (grey, grey, grey + int(rng.integers(0, 16)))  # black to slate: a table, not a blue object
    img = Image.new("RGB", (big, big), background)
    pen = ImageDraw.Draw(img)
    for o in scene.objects:
        colour = BASE[o.color]
        if style == "shades":
            colour = SHADES[o.color][int(rng.integers(len(SHADES[o.color])))]
        pts = _outline_points(o.shape, o.x, o.y, o.width, big, rng if style == "jitter" else None, 0.02)
        if style == "outline":
            pen.polygon(pts, fill=colour, outline=(0, 0, 0), width=max(2, round(0.008 * big)))
        else:
            pen.polygon(pts, fill=colour)
    if scene.pointer is not None:  # a black dot with a white centre, about 3.5% of the picture across
        px, py, r = scene.pointer[0] * big, scene.pointer[1] * big, 0.0175 * big
        pen.ellipse([px - r, py - r, px + r, py + r], fill=(0, 0, 0))
        pen.ellipse([px - r / 2.2, py - r / 2.2, px + r / 2.2, py + r / 2.2], fill=(250, 250, 250))
    img = img.resize((size, size), Image.LANCZOS)
    if style == "photo":
        img = img.filter(ImageFilter.GaussianBlur(radius=float(rng.uniform(0.6, 1.2)) * size / 256))
        arr = np.asarray(img, np.float64) + rng.normal(0, 5, (size, size, 3))
        img = Image.fromarray(np.clip(arr, 0, 255).astype(np.uint8))
        buf = io.BytesIO()
        img.save(buf, format="JPEG", quality=int(rng.integers(60, 85)))
        img = Image.open(io.BytesIO(buf.getvalue())).convert("RGB")
    return np.asarray(img, np.uint8).copy()
