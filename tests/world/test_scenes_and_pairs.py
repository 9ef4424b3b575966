"""Generated scenes and the nudges that decide whether an example is well posed."""

from __future__ import annotations

import numpy as np
import pytest

from vccjax.machine.config import DEFAULT_CONFIG as CFG
from vccjax.world.pairs import Jitter, _nudges
from vccjax.world.scenes import drawn_cover, random_scene
from vccjax.machine.geometry import object_pixels
from vccjax.machine.instructions import SHAPES
from vccjax.machine.geometry import shape_polygon
from vccjax.machine.scene import Scene, SceneObject, to_units


@pytest.mark.parametrize("shape", SHAPES)
def test_drawn_cover_holds_the_mask_and_the_drawn_outline(shape):
    rng = np.random.default_rng(1)
    for _ in range(200):
        w = float(rng.uniform(0.04, 0.2))
        x, y = (float(v) for v in rng.uniform(0.2, 0.8, size=2))
        cover = set(zip(*(a.tolist() for a in drawn_cover(shape, w, x, y, CFG))))
        mask = set(zip(*(a.tolist() for a in object_pixels(shape, w, to_units(x, CFG), to_units(y, CFG), CFG))))
        assert mask <= cover, (shape, w, x, y)
        # every point of the drawn outline lies in a covered pixel,
        t = np.linspace(0, 1, 400, endpoint=False)
        if shape == "circle":
            pts = np.stack([x + w / 2 * np.cos(2 * np.pi * t), y + w / 2 * np.sin(2 * np.pi * t)], 1)
        else:
            poly = shape_polygon(shape, x, y, w, 1.0)
            nxt = np.roll(poly, -1, axis=0)
            pts = np.concatenate([a + t[:, None] * (b - a) for a, b in zip(poly, nxt)])
        # to an eighth of a pixel (the cover is traced at 8x; an edge that enters a pixel by
        # less paints nothing visible there)
        c = np.array([x, y])
        d = np.linalg.norm(pts - c, axis=1, keepdims=True)
        pts = c + (pts - c) * (1 - 0.15 / CFG.raster / d)
        pix = np.floor(pts * CFG.raster).astype(int)
        assert {(int(r), int(c)) for c, r in pix} <= cover, (shape, w, x, y)

def test_generated_shapes_keep_their_drawn_pixels_apart():
    rng = np.random.default_rng(7)
    for _ in range(30):
        sc = random_scene(rng, (6, 8), widths=(0.04, 0.2), cfg=CFG)
        owner = np.full((CFG.raster, CFG.raster), -1)
        for i, o in enumerate(sc.objects):
            rows, cols = drawn_cover(o.shape, o.width, o.x, o.y, CFG)
            keep = (rows >= 0) & (rows < CFG.raster) & (cols >= 0) & (cols < CFG.raster)
            for r, c in zip(rows[keep], cols[keep]):
                near = owner[max(r - 2, 0):r + 3, max(c - 2, 0):c + 3]
                assert not ((near >= 0) & (near != i)).any(), "two drawn shapes within the gap"
                owner[r, c] = i


def test_nudges_cover_every_direction_and_stay_in_bounds():
    j = Jitter()
    sc = Scene((SceneObject("star", "blue", 0.4, 0.4, 0.1), SceneObject("circle", "red", 0.7, 0.6, 0.12)),
               pointer=(0.2, 0.8))
    n = len(sc.objects)
    nudged = list(_nudges(sc, j, np.random.default_rng(0)))
    alone = n * j.object_corners + 4  # each object alone, then the pointer alone
    assert len(nudged) == alone + j.directions + j.trials + j.small_trials
    for n_ in nudged:
        for o, m in zip(sc.objects, n_.objects):
            assert abs(m.x - o.x) <= j.centre + 1e-12 and abs(m.y - o.y) <= j.centre + 1e-12
            assert abs(m.width - o.width) <= j.width + 1e-12
        assert abs(n_.pointer[0] - 0.2) <= j.pointer + 1e-12 and abs(n_.pointer[1] - 0.8) <= j.pointer + 1e-12
    for i in range(n):  # object i alone, to each diagonal corner of its box
        trials = nudged[i * j.object_corners:(i + 1) * j.object_corners]
        corners = set()
        for t in trials:
            moved = [k for k, (o, m) in enumerate(zip(sc.objects, t.objects)) if (o.x, o.y) != (m.x, m.y)]
            assert moved == [i] and t.pointer == sc.pointer
            m = t.objects[i]
            corners.add((round((m.x - sc.objects[i].x) / j.centre), round((m.y - sc.objects[i].y) / j.centre)))
        assert corners == {(1, 1), (-1, -1), (1, -1), (-1, 1)}
    for t in nudged[n * j.object_corners:alone]:  # the pointer alone
        assert t.objects == sc.objects and t.pointer != sc.pointer
    angles = set()
    for t in nudged[alone:alone + j.directions]:  # whole-scene shifts: every object and the pointer alike
        d = np.array([[m.x - o.x, m.y - o.y] for o, m in zip(sc.objects, t.objects)])
        assert np.allclose(d, d[0]) and np.isclose(np.hypot(*d[0]), j.centre)
        assert np.allclose(np.subtract(t.pointer, sc.pointer) / j.pointer, d[0] / j.centre)
        angles.add(round(float(np.degrees(np.arctan2(d[0, 1], d[0, 0]))) % 360))
    assert angles == {0, 45, 90, 135, 180, 225, 270, 315}


def test_grow_is_cv2_dilate_with_a_square_kernel():
    """Scene generation keeps objects apart with a numpy dilation (the world imports no
    OpenCV); it must equal OpenCV's, which generated the shipped examples."""
    import cv2

    from vccjax.world.scenes import _grow

    rng = np.random.default_rng(0)
    for g in range(4):
        for _ in range(20):
            m = (rng.random((64, 64)) < 0.02).astype(np.uint8)
            assert np.array_equal(cv2.dilate(m, np.ones((2 * g + 1, 2 * g + 1), np.uint8)) > 0, _grow(m > 0, g))
