"""A rollout as a video: the recorded states rendered from the oblique camera, beside
the camera's rectified view of the start, as MP4 (OpenCV's FFMPEG writer)."""

from __future__ import annotations

from pathlib import Path

import cv2
import mujoco
import numpy as np

from robot.control import TICK


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
    out = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*fourcc), fps, (width, size))
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
