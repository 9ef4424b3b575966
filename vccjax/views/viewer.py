"""Traces drawn: one panel per executed instruction, as a PNG sheet or an animated GIF.

A panel shows the blackboard (the objects as the machine holds them, the pointer, the
imagined object hatched in violet), the fovea (blue cross-hair ring) and its history
(grey path, numbered), the hand (orange fork; the held object boxed in orange), and
attention (the footer's "attend shape/colour" filters, * for any, and the attended
list; each listed object numbered in magenta by its place in the list, the attended
one boxed in magenta). The header names
the instruction with its argument; a failed instruction turns the panel's frame red and
its footer gives the reason.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from vccjax.machine.geometry import imagined_pixels
from vccjax.machine.instructions import COLORS, SHAPES
from vccjax.machine.reference import RefMachine
from vccjax.vision.render import render
from vccjax.machine.scene import Scene
from vccjax.views.trace import Frame

HEADER, FOOTER, MARGIN = 34, 48, 6
FONT = cv2.FONT_HERSHEY_SIMPLEX
INK, GREY, RED = (30, 30, 30), (150, 150, 150), (210, 30, 30)
FOVEA, HAND, ATTEND, IMAGINED = (40, 90, 230), (245, 140, 20), (220, 0, 200), (150, 90, 210)


def _blackboard(m: RefMachine, input_frame: bool) -> Scene:
    """What the machine holds (before scene_parse, or for the input panel: the scene)."""
    return m.scene if input_frame or not m.blackboard.parsed else m.output_scene()


def _px(v: float, units: int, size: int) -> int:
    return int(round(v / units * size))


def put_text(img: np.ndarray, text: str, org: tuple[int, int], color=INK, scale: float = 0.42) -> None:
    cv2.putText(img, text, org, FONT, scale, color, 1, cv2.LINE_AA)


def fit_text(text: str, width: int, scale: float = 0.42) -> str:
    """Cut `text` with an ellipsis to fit `width` pixels."""
    while len(text) > 4 and cv2.getTextSize(text, FONT, scale, 1)[0][0] > width:
        text = text[:-4] + "..."
    return text


def _box(img: np.ndarray, m: RefMachine, i: int, color, size: int, pad: int, thickness: int) -> None:
    u, (ox, oy) = m.cfg.units, m.centre(i)
    h = m.widths[i] / 2 * size
    x, y = _px(ox, u, size), _px(oy, u, size)
    cv2.rectangle(img, (int(x - h) - pad, int(y - h) - pad), (int(x + h) + pad, int(y + h) + pad), color, thickness,
                  cv2.LINE_AA)


def _scene_view(m: RefMachine, size: int, input_frame: bool) -> np.ndarray:
    img = render(_blackboard(m, input_frame), size=max(64, size)).copy()
    u, b, a = m.cfg.units, m.blackboard, m.attention
    if b.imagined_kind >= 0 and not input_frame:  # hatched violet footprint
        rows, cols = imagined_pixels(b.imagined_kind, *b.imagined_position, m.cfg)
        mask = np.zeros((m.cfg.raster, m.cfg.raster), np.uint8)
        mask[rows, cols] = 1
        mask = cv2.resize(mask, (size, size), interpolation=cv2.INTER_NEAREST).astype(bool)
        yy, xx = np.mgrid[:size, :size]
        hatch = ((xx + yy) // 3) % 3 == 0
        img[mask] = (0.6 * img[mask] + 0.4 * np.array(IMAGINED)).astype(np.uint8)
        img[mask & hatch] = IMAGINED
    if input_frame or not b.parsed:
        return img
    pts = [(_px(x, u, size), _px(y, u, size)) for x, y in m.fovea.history]
    if len(pts) > 1:
        cv2.polylines(img, [np.array(pts, np.int32)], False, GREY, 1, cv2.LINE_AA)
    for k, p in enumerate(pts[1:], 1):
        cv2.circle(img, p, 2, GREY, -1, cv2.LINE_AA)
        put_text(img, str(k), (p[0] + 3, p[1] - 3), GREY, 0.3)
    f = (_px(m.fovea.position[0], u, size), _px(m.fovea.position[1], u, size))
    cv2.circle(img, f, 9, FOVEA, 2, cv2.LINE_AA)
    cv2.line(img, (f[0] - 13, f[1]), (f[0] + 13, f[1]), FOVEA, 1, cv2.LINE_AA)
    cv2.line(img, (f[0], f[1] - 13), (f[0], f[1] + 13), FOVEA, 1, cv2.LINE_AA)
    for rank, i in enumerate(a.attended_list if not a.stale else []):
        if b.alive[i]:
            (x, y), h = m.centre(i), m.widths[i] / 2 * size
            put_text(img, str(rank + 1), (int(_px(x, u, size) + h) + 2, int(_px(y, u, size) - h) + 4), ATTEND, 0.38)
    if a.attended >= 0 and b.alive[a.attended]:
        _box(img, m, a.attended, ATTEND, size, 3, 1)
    if m.hand.held >= 0:
        _box(img, m, m.hand.held, HAND, size, 6, 2)
    hx, hy = _px(m.hand.position[0], u, size), _px(m.hand.position[1], u, size)  # a two-pronged fork, opening down
    cv2.line(img, (hx - 7, hy - 12), (hx + 7, hy - 12), HAND, 2, cv2.LINE_AA)
    cv2.line(img, (hx - 7, hy - 12), (hx - 7, hy - 2), HAND, 2, cv2.LINE_AA)
    cv2.line(img, (hx + 7, hy - 12), (hx + 7, hy - 2), HAND, 2, cv2.LINE_AA)
    cv2.line(img, (hx, hy - 12), (hx, hy - 20), HAND, 2, cv2.LINE_AA)
    return img


def panel(frame: Frame, size: int = 256) -> np.ndarray:
    """One frame as an RGB image (size wide)."""
    m, input_frame = frame.machine, frame.pc < 0
    img = np.full((HEADER + size + FOOTER, size + 2 * MARGIN, 3), 255, np.uint8)
    img[HEADER:HEADER + size, MARGIN:MARGIN + size] = _scene_view(m, size, input_frame)
    cv2.rectangle(img, (MARGIN - 1, HEADER - 1), (MARGIN + size, HEADER + size), (200, 200, 200), 1)  # the workspace
    width = size + 2 * MARGIN - 8
    if input_frame:
        put_text(img, "input scene", (4, 14), INK, 0.45)
    else:
        loop = f", iteration {frame.iteration + 1}" if frame.iteration else ""
        put_text(img, f"step {frame.step + 1} (instruction {frame.pc}{loop})", (4, 13), GREY, 0.36)
        put_text(img, fit_text(frame.instruction, width, 0.48), (4, 29), RED if frame.failed else INK, 0.48)
    y = HEADER + size + 15
    if frame.failed:
        put_text(img, fit_text(f"FAILED: {m.fail_reason}", width), (4, y), RED)
        put_text(img, "the machine stops here", (4, y + 17), RED, 0.38)
    elif not input_frame and m.blackboard.parsed:
        a, b, i = m.attention, m.blackboard, m.hand.held
        shape = "*" if a.shape_filter < 0 else SHAPES[a.shape_filter]
        color = "*" if a.color_filter < 0 else COLORS[a.color_filter]
        listed = "list stale" if a.stale else f"{len(a.attended_list)} listed, at {a.cursor + 1}"
        put_text(img, fit_text(f"attend {shape}/{color}: {listed}", width), (4, y), ATTEND, 0.38)
        held = "hand empty" if i < 0 else f"holds {COLORS[b.color[i]]} {SHAPES[m.shapes[i]]}"
        kind = b.imagined_kind
        imagined = "" if kind < 0 else ", imagining a " + ("circle" if kind == 0 else "line")
        n = len(m.fovea.history) - 1
        fixations = f"{n} fixation" + ("" if n == 1 else "s")
        put_text(img, fit_text(f"{held}, {fixations}{imagined}", width), (4, y + 17), INK, 0.38)
    if frame.failed:
        cv2.rectangle(img, (0, 0), (img.shape[1] - 1, img.shape[0] - 1), RED, 3)
    return img


def sheet(frames: Sequence[Frame], size: int = 256, columns: int = 6) -> np.ndarray:
    """Every panel, left to right and top to bottom, on one RGB image."""
    panels = [panel(f, size) for f in frames]
    h, w = panels[0].shape[:2]
    columns = max(1, min(columns, len(panels)))
    rows = -(-len(panels) // columns)
    out = np.full((rows * (h + 4), columns * (w + 4), 3), 235, np.uint8)
    for k, p in enumerate(panels):
        r, c = divmod(k, columns)
        out[r * (h + 4):r * (h + 4) + h, c * (w + 4):c * (w + 4) + w] = p
    return out


def write_trace(frames: Sequence[Frame], path: str | Path, size: int = 256, columns: int = 6,
                seconds_per_step: float = 0.8) -> Path:
    """A PNG sheet (.png) or an animated GIF (.gif, one panel per frame, the last held)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".png", ".gif"):
        raise ValueError(f"{path}: a trace is written as .png or .gif")
    if not frames:
        raise ValueError("no frames to draw")
    from vccjax import files

    if suffix == ".png":
        with files.whole(path) as tmp:
            if not cv2.imwrite(str(tmp), cv2.cvtColor(sheet(frames, size, columns), cv2.COLOR_RGB2BGR)):
                raise OSError(f"{path}: could not be written")
        return path
    from PIL import Image  # Pillow: OpenCV writes no GIF

    images = [Image.fromarray(panel(f, size)) for f in frames]
    durations = [int(seconds_per_step * 1000)] * (len(images) - 1) + [int(seconds_per_step * 3000)]
    with files.whole(path) as tmp:
        images[0].save(tmp, save_all=True, append_images=images[1:], duration=durations, loop=0, optimize=True)
    return path
