"""The arm camera's parse measured apart (`vcc robot perception`): the same scenes under
each condition, a moved camera read through the calibrated pose."""

from __future__ import annotations

import json

import robot  # noqa: F401  (sets MUJOCO_GL before mujoco is imported)
from robot.perception_sweep import Condition, sweep


def test_nominal_scenes_parse_exact_and_a_turned_camera_moves_the_centres():
    table = sweep(3, seed=1, conditions=(Condition("nominal"), Condition("turned", tilt_deg=1.0)))
    nominal, turned = table["nominal"], table["turned"]
    assert nominal["scenes"] == turned["scenes"] == 3 and nominal["objects"] == turned["objects"] >= 6
    assert nominal["scenes_exact"] == 3 and nominal["objects_exact"] == nominal["objects"]
    # 1 degree at 1.25 m moves the image of the table by about 2 cm: beyond the 8 mm tolerance
    assert turned["largest_centre_error_m"] > 0.01 > nominal["largest_centre_error_m"]
    assert turned["objects_exact"] < turned["objects"]
    assert json.loads(json.dumps(table)) == table


def test_the_perception_command_refuses_bad_options(capsys):
    from vcc.cli import main

    for argv, message in [(["robot", "perception", "--out", "x.json", "--scenes", "0"], "argument --scenes: 0 is out of range"),
                          (["robot", "perception", "--out", "x.txt"], "argument --out: x.txt: write .json")]:
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1
