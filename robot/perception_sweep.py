"""The arm's camera measured apart: how often the parse of a rendered table is exact
(`robot.truth`), under nominal conditions and harder ones.

Scenes are the suite's own (scenarios drawn for the default choice of learned concepts,
in turn). A condition changes what the camera sees, never the calibration the parser
uses: dimmer or brighter light, or the camera's true pose off its calibrated one by a few
millimetres and degrees (a bumped mount), the rectification still made with the
calibrated pose. At 1.25 m above the table a turn of 0.1 degree moves the image of
the table by 2 mm, so a turned camera tests the 8 mm centre tolerance more than the
parser. No physics runs, so a sweep of a few hundred scenes takes minutes.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np


@dataclasses.dataclass(frozen=True)
class Condition:
    name: str
    light: float = 1.0  # scale of every light's diffuse and ambient part
    shift_mm: float = 0.0  # camera position off its calibration, per axis, uniform in +-shift_mm
    tilt_deg: float = 0.0  # camera rotation off its calibration, about a random axis


CONDITIONS: tuple[Condition, ...] = (
    Condition("nominal"),
    Condition("dim light (x0.6)", light=0.6),
    Condition("bright light (x1.4)", light=1.4),
    Condition("camera moved 2 mm", shift_mm=2.0),
    Condition("camera moved 5 mm", shift_mm=5.0),
    Condition("camera turned 0.1 deg", tilt_deg=0.1),
    Condition("camera turned 0.25 deg", tilt_deg=0.25),
    Condition("camera turned 0.5 deg", tilt_deg=0.5),
    Condition("camera turned 1 deg", tilt_deg=1.0),
)


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    axis = axis / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def sweep(scenes: int, seed: int = 0, conditions: Sequence[Condition] = CONDITIONS,
          progress: Callable[[int], None] | None = None) -> dict:
    """{condition name: tally} over `scenes` suite scenes, each condition on the same scenes."""
    import mujoco

    from robot.camera import Camera
    from robot.choice import default_choice
    from robot.mjcf import scene_xml
    from robot.scenario import draw
    from robot.sources import RUN_OF_RECORD, Programs
    from robot.truth import check_parse
    from vccjax.errors import SceneError

    programs = Programs(str(RUN_OF_RECORD))
    names = default_choice(programs.table)
    model = mujoco.MjModel.from_xml_string(scene_xml())
    data = mujoco.MjData(model)
    camera = Camera(model)
    cam = camera.cam
    base = (model.cam_pos[cam].copy(), model.cam_quat[cam].copy())
    lights = (model.light_diffuse.copy(), model.vis.headlight.diffuse.copy(), model.vis.headlight.ambient.copy(),
              model.light_ambient.copy())
    rng = np.random.default_rng([seed, 0x9E7])
    staged = []
    for k in range(scenes):
        try:
            staged.append(draw(programs.of(names[k % len(names)]), seed * 100_003 + k))
        except SceneError:
            continue
    out = {}
    for cond in conditions:
        model.light_diffuse[:] = lights[0] * cond.light
        model.vis.headlight.diffuse[:] = lights[1] * cond.light
        model.vis.headlight.ambient[:] = lights[2] * cond.light
        model.light_ambient[:] = lights[3] * cond.light
        tally = {"scenes": 0, "scenes_exact": 0, "objects": 0, "objects_exact": 0, "parse_errors": 0,
                 "centre_errors_m": []}
        for sc in staged:
            data.qpos[:] = sc.qpos(model)
            sc.dress(model, data)
            model.cam_pos[cam], model.cam_quat[cam] = base
            mujoco.mj_forward(model, data)
            calibrated = (data.cam_xpos[cam].copy(), data.cam_xmat[cam].reshape(3, 3).copy())
            if cond.shift_mm or cond.tilt_deg:  # the mount bumped: the image moves, the calibration does not
                model.cam_pos[cam] = base[0] + rng.uniform(-1, 1, 3) * cond.shift_mm / 1000
                turn = _rotation(rng.normal(size=3), np.deg2rad(cond.tilt_deg))
                q = np.empty(4)
                mujoco.mju_mat2Quat(q, (turn @ calibrated[1]).ravel())
                model.cam_quat[cam] = q
                mujoco.mj_forward(model, data)
            tally["scenes"] += 1
            tally["objects"] += len(sc.scene.objects)
            try:
                parsed, _ = camera.scene(data, pose=calibrated)
            except SceneError:
                tally["parse_errors"] += 1
                if progress:
                    progress(1)
                continue
            c = check_parse(sc.scene, parsed)
            tally["scenes_exact"] += c.exact
            tally["objects_exact"] += c.exact_objects
            tally["centre_errors_m"].append(c.centre_error_m)
            if progress:
                progress(1)
        errs = tally.pop("centre_errors_m")
        tally["largest_centre_error_m"] = float(max(errs, default=0.0))
        tally["mean_largest_centre_error_m"] = float(np.mean(errs)) if errs else 0.0
        out[cond.name] = {**dataclasses.asdict(cond), **tally}
    model.cam_pos[cam], model.cam_quat[cam] = base
    camera.close()
    return out
