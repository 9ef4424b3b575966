"""A rollout as a video: the recorded states rendered from the oblique camera, beside
the camera's rectified view of the start, as MP4 (OpenCV's FFMPEG writer)."""

from __future__ import annotations

from pathlib import Path

import cv2
import mujoco
import numpy as np

from robot.control import TICK
from vccjax import files


def write_video(model: mujoco.MjModel, scenario, qs: np.ndarray, path: str | Path, every: int,
                size: int = 360, camera: str = "oblique") -> int:
    """Write frames for recorded qpos `qs` (T, nq), one per `every` control ticks; returns
    the frame count. The format follows the suffix: .mp4 (mp4v) or .avi (MJPG)."""
    path = Path(path)
    fourcc = {".mp4": "mp4v", ".avi": "MJPG"}.get(path.suffix.lower())
    if fourcc is None:
        raise ValueError(f"{path}: write .mp4 or .avi")
    data = mujoco.MjData(model)
    scenario.dress(model, data)
    fps = 1.0 / (every * TICK)
    width = size * 16 // 9 // 2 * 2  # codecs want even sizes
    with files.whole(path) as tmp:
        out = cv2.VideoWriter(str(tmp), cv2.VideoWriter_fourcc(*fourcc), fps, (width, size))
        if not out.isOpened():
            raise OSError(f"{path}: OpenCV cannot write this video here")
        with mujoco.Renderer(model, size, width) as r:
            for q in qs:
                data.qpos[:] = q
                mujoco.mj_forward(model, data)
                r.update_scene(data, camera=camera)
                out.write(cv2.cvtColor(r.render(), cv2.COLOR_RGB2BGR))
        out.release()
    return len(qs)


def write_frames(model: mujoco.MjModel, scenario, qs: np.ndarray, path: str | Path, count: int = 6,
                 size: int = 240, camera: str = "oblique") -> int:
    """Write `count` key frames of recorded qpos `qs`, evenly spaced from start to end, side
    by side as one picture (PNG or JPEG); returns the frame count."""
    path = Path(path)
    if path.suffix.lower() not in (".png", ".jpg", ".jpeg"):
        raise ValueError(f"{path}: write .png or .jpg")
    data = mujoco.MjData(model)
    scenario.dress(model, data)
    width = size * 4 // 3
    shots = []
    with mujoco.Renderer(model, size, width) as r:
        for t in np.linspace(0, len(qs) - 1, count).round().astype(int):
            data.qpos[:] = qs[t]
            mujoco.mj_forward(model, data)
            r.update_scene(data, camera=camera)
            shots.append(r.render())
    gap = np.full((size, 4, 3), 255, np.uint8)
    strip = np.concatenate([x for s in shots for x in (s, gap)][:-1], axis=1)
    with files.whole(path) as tmp:
        if not cv2.imwrite(str(tmp), cv2.cvtColor(strip, cv2.COLOR_RGB2BGR)):
            raise OSError(f"{path}: could not be written")
    return count
