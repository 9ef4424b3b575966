"""The camera above the table: rendering, calibration, and the scene the VCC sees.

The image goes through the camera's calibration (pinhole model from the MJCF camera:
its pose and field of view) into a top-down view of the workspace square, and from
there through the project's own OpenCV `scene_parse` (`vccjax.vision.perception`), exactly
as a schematic image would. The table plane is taken at `PLANE_Z`, about mid-height of
the objects, so that an object's silhouette is centred where its body is.
"""

from __future__ import annotations

import cv2
import mujoco
import numpy as np

from robot.world import to_table
from vccjax.vision.perception import parse_image
from vccjax.machine.scene import Scene

IMAGE = 640  # rendered pixels per side
VIEW = 384  # pixels per side of the rectified workspace image
PLANE_Z = 0.018


class Camera:
    """One offscreen renderer for a model (EGL or OSMesa, set by MUJOCO_GL)."""

    def __init__(self, model: mujoco.MjModel, name: str = "top", size: int = IMAGE):
        self.model, self.size, self.cam = model, size, model.camera(name).id
        self.renderer = mujoco.Renderer(model, size, size)

    def image(self, data: mujoco.MjData) -> np.ndarray:
        """(size, size, 3) uint8 RGB."""
        self.renderer.update_scene(data, camera=self.cam)
        return self.renderer.render().copy()

    def project(self, data: mujoco.MjData, points: np.ndarray,
                pose: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """World points (N, 3) to pixel (column, row) through the pinhole model; `pose`
        (position, 3x3 rotation) is the calibration, by default the camera's true pose."""
        pos, rot = pose if pose is not None else (data.cam_xpos[self.cam], data.cam_xmat[self.cam].reshape(3, 3))
        p = (np.asarray(points, float) - pos) @ rot  # camera frame: looks along -z, image up is +y
        f = 0.5 * self.size / np.tan(np.deg2rad(self.model.cam_fovy[self.cam]) / 2)
        return np.stack([0.5 * self.size + f * p[:, 0] / -p[:, 2], 0.5 * self.size - f * p[:, 1] / -p[:, 2]], 1)

    def rectify(self, data: mujoco.MjData, image: np.ndarray, size: int = VIEW,
                pose: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """The workspace square seen from straight above: (size, size, 3) RGB, through the
        calibration `pose` (default: the true pose)."""
        corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
        world = np.c_[to_table(corners[:, 0], corners[:, 1]), np.full(4, PLANE_Z)]
        src = self.project(data, world, pose).astype(np.float32) - 0.5  # pixel centres
        dst = (corners * size - 0.5).astype(np.float32)
        h = cv2.getPerspectiveTransform(src, dst)
        return cv2.warpPerspective(image, h, (size, size), flags=cv2.INTER_LINEAR, borderValue=(255, 255, 255))

    def scene(self, data: mujoco.MjData, pose: tuple[np.ndarray, np.ndarray] | None = None
              ) -> tuple[Scene, np.ndarray]:
        """The VCC's input scene parsed from a fresh image, and the rectified view."""
        view = self.rectify(data, self.image(data), pose=pose)
        return parse_image(view), view

    def close(self) -> None:
        self.renderer.close()
