"""The robot's scene in MJCF, generated from `world`: a table, a 6-joint arm of UR5e
kinematics with a two-finger gripper, a camera above the table, object slots, a pointer
marker and distractors.

One model serves every scenario, so that one compiled MJX rollout serves them all:
a scenario differs only in state (which slots stand on the table and where, the
pointer's and distractors' mocap positions) and in what only the camera sees (colours,
table texture). Physics settings follow measured facts on this CPU
(docs/robot.md, "MJX on CPU"): 5 ms Newton steps, 5 iterations, pyramidal cones,
contacts only between pads, objects and the table. Friction is made 3 times stiffer
than the normal force (`impratio`): with 1, a ball held between the flat pads crept
down about 5 mm/s and reached the table during long carries (docs/robot.md).
"""

from __future__ import annotations

import functools

import numpy as np

from robot.world import (APART, BODIES, KNOB, TABLE_CENTRE, TABLE_HALF, TEXTURES, WORKSPACE_CENTRE, WORKSPACE_SIDE,
                         Body)

ARM_JOINTS = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3")
HOME = (-1.5708, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)  # tool down, beside the workspace
FINGER_OPEN = 0.045  # metres each finger travels from the centre: 9 cm between the pads
TCP_DEPTH = 0.115  # tool centre point below the flange, 1.5 cm above the pads' tips
PAD_HALF = (0.006, 0.011, 0.040)  # pad half extents: thickness (closing axis), width, length
# (upright capsule pads would cut MJX's static contacts from 113 to 93, but held a third of the grasps)
N_DISTRACTORS = 3
CAMERA = {"pos": (WORKSPACE_CENTRE[0], WORKSPACE_CENTRE[1], 1.25), "fovy": 32.0}
# contact groups: table 1, objects 2, pads 4 (objects touch all three; pads never the table)
_TABLE, _OBJECT, _PAD = 1, 2, 4


def _fmt(v) -> str:
    return " ".join(f"{float(x):.6g}" for x in np.ravel(v))


def mesh_vertices(body: Body) -> np.ndarray | None:
    """(V, 3) vertices of a body's mesh, centred on its plate or bounding box (None for a
    primitive). Under 32 vertices: MJX's hull collisions are measured fast up to there."""
    r, h = body.size / 2, body.height / 2
    if body.kind in ("triangle", "star"):  # the VCC's outline (image up is world +x), as a plate
        outline = _outline(body.kind, r)
        return np.concatenate([np.c_[outline, np.full(len(outline), -h)], np.c_[outline, np.full(len(outline), h)],
                               [[0.0, 0.0, -h], [0.0, 0.0, h]]])
    if body.kind == "lemon":  # a round body with a small flat bottom, so it stands
        ry = r * 0.86
        # the widest band is upright (rings in line), so a pad squeezing it pushes straight in, not down
        rings = ((-h, 0.6, 6, 0.0), (-0.3 * h, 1.0, 10, 0.0), (0.3 * h, 1.0, 10, 0.0))
        pts = [(s * r * np.cos(t), s * ry * np.sin(t), z)
               for z, s, k, turn in rings for t in np.linspace(0, 2 * np.pi, k, endpoint=False) + turn]
        pts.append((0.0, 0.0, h))
        return np.array(pts)
    return None


def _outline(kind: str, r: float) -> np.ndarray:
    """The plate's outline in the body frame (world x = image up, world y = image left),
    counter-clockwise seen from above; the centre is the VCC object's centre."""
    from vccjax.machine.geometry import star_polygon

    if kind == "star":
        img = star_polygon(r)  # image (x right, y down), first point up
    else:  # apex up at -r, base at +r, base width 2r
        img = np.array([[0.0, -r], [-r, r], [r, r]])
    world = np.stack([-img[:, 1], -img[:, 0]], 1)
    area = np.sum(world[:, 0] * np.roll(world[:, 1], -1) - np.roll(world[:, 0], -1) * world[:, 1])
    return world if area > 0 else world[::-1]


def mesh_faces(body: Body) -> np.ndarray | None:
    """Triangles of a plate's mesh (outward normals), so that a star renders as a star (its
    collision is its convex hull); None where the hull of the vertices is the shape."""
    if body.kind not in ("triangle", "star"):
        return None
    n = len(_outline(body.kind, body.size / 2))
    bottom, top = n * 2, n * 2 + 1  # the centre vertices
    faces = []
    for i in range(n):
        j = (i + 1) % n
        faces += [(bottom, j, i), (top, n + i, n + j), (i, j, n + j), (i, n + j, n + i)]
    return np.array(faces)


def _object_xml(k: int, body: Body) -> str:
    common = (f'contype="{_OBJECT}" conaffinity="{_TABLE | _OBJECT | _PAD}" condim="3" friction="0.9 0.005 0.0001" '
              f'density="900" rgba="0.5 0.5 0.5 1" material="matte"')
    if body.kind == "box":
        geom = f'<geom name="obj{k}" type="box" size="{_fmt([body.size / 2, body.size / 2, body.height / 2])}" {common}/>'
    elif body.kind == "ball":  # rolling friction (condim 6), so that a ball set down stays
        common = common.replace('condim="3" friction="0.9 0.005 0.0001"', 'condim="6" friction="0.9 0.02 0.02"')
        geom = f'<geom name="obj{k}" type="sphere" size="{body.size / 2:.6g}" {common}/>'
    else:
        geom = f'<geom name="obj{k}" type="mesh" mesh="mesh_{body.name}" {common}/>'
    if body.knob:  # gripped like a small box; coloured with the plate (`knob_geom`)
        side, tall = KNOB
        geom += (f'<geom name="{knob_geom(k)}" type="box" size="{_fmt([side / 2, side / 2, tall / 2])}" '
                 f'pos="0 0 {body.height / 2 + tall / 2:.6g}" {common}/>')
    x, y = parked_xy(k)
    return (f'<body name="slot{k}" pos="{_fmt([x, y, body.height / 2])}">'
            f'<freejoint name="slot{k}"/>{geom}</body>')


def knob_geom(k: int) -> str:
    return f"obj{k}_knob"


def parked_xy(k: int) -> tuple[float, float]:
    """Where an unused slot waits: on the floor plane, far out of reach and of view."""
    return (-1.5 - 0.2 * k, 1.5)


def _arm_xml() -> str:
    p, f = PAD_HALF, FINGER_OPEN
    link = 'contype="0" conaffinity="0" rgba="0.7 0.72 0.75 1" material="metal"'
    pad = (f'contype="{_PAD}" conaffinity="{_OBJECT}" condim="3" friction="1.5 0.005 0.0001" '
           f'solref="0.01 1" solimp="0.99 0.999 0.001" rgba="0.15 0.15 0.15 1" material="matte"')
    pz = TCP_DEPTH + 0.015 - p[2]  # pads end 1.5 cm below the tool centre point
    return f"""
    <body name="base" pos="0 0 0">
      <geom type="cylinder" size="0.075 0.045" pos="0 0 0.045" {link}/>
      <body name="shoulder" pos="0 0 0.163" gravcomp="1">
        <joint name="shoulder_pan" axis="0 0 1" range="-6.28 6.28" armature="0.1" damping="10"/>
        <geom type="capsule" size="0.06" fromto="0 0 -0.06 0 0 0.06" {link}/>
        <body name="upper_arm" pos="0 0.138 0" quat="1 0 1 0" gravcomp="1">
          <joint name="shoulder_lift" axis="0 1 0" range="-6.28 6.28" armature="0.1" damping="10"/>
          <geom type="capsule" size="0.055" fromto="0 0 0 0 0 0.425" {link}/>
          <body name="forearm" pos="0 -0.131 0.425" gravcomp="1">
            <joint name="elbow" axis="0 1 0" range="-3.14 3.14" armature="0.1" damping="10"/>
            <geom type="capsule" size="0.045" fromto="0 0 0 0 0 0.392" {link}/>
            <body name="wrist_1" pos="0 0 0.392" quat="1 0 1 0" gravcomp="1">
              <joint name="wrist_1" axis="0 1 0" range="-6.28 6.28" armature="0.05" damping="2"/>
              <geom type="capsule" size="0.04" fromto="0 -0.01 0 0 0.11 0" {link}/>
              <body name="wrist_2" pos="0 0.127 0" gravcomp="1">
                <joint name="wrist_2" axis="0 0 1" range="-6.28 6.28" armature="0.05" damping="2"/>
                <geom type="capsule" size="0.04" fromto="0 0 0 0 0 0.1" {link}/>
                <body name="wrist_3" pos="0 0 0.1" gravcomp="1">
                  <joint name="wrist_3" axis="0 1 0" range="-6.28 6.28" armature="0.05" damping="2"/>
                  <geom type="cylinder" size="0.04 0.012" pos="0 0.088 0" quat="1 1 0 0" {link}/>
                  <body name="gripper" pos="0 0.1 0" quat="-1 1 0 0" gravcomp="1">
                    <site name="flange"/>
                    <site name="tcp" pos="0 0 {TCP_DEPTH}" size="0.005"/>
                    <geom type="box" size="{f + 0.02:.4g} 0.02 0.02" pos="0 0 0.02" {link}/>
                    <body name="finger_a" pos="0 0 0.04" gravcomp="1">
                      <joint name="finger_a" type="slide" axis="1 0 0" range="0 {f}" armature="0.01" damping="5"/>
                      <geom name="pad_a" type="box" size="{_fmt(p)}" pos="{p[0]} 0 {pz - 0.04:.4g}" {pad}/>
                    </body>
                    <body name="finger_b" pos="0 0 0.04" gravcomp="1">
                      <joint name="finger_b" type="slide" axis="-1 0 0" range="0 {f}" armature="0.01" damping="5"/>
                      <geom name="pad_b" type="box" size="{_fmt(p)}" pos="{-p[0]} 0 {pz - 0.04:.4g}" {pad}/>
                    </body>
                  </body>
                </body>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>"""


def _assets() -> str:
    meshes = "".join(f'<mesh name="mesh_{b.name}" vertex="{_fmt(mesh_vertices(b))}"'
                     + (f' face="{_fmt(mesh_faces(b))}"' if mesh_faces(b) is not None else "") + "/>"
                     for b in BODIES if mesh_vertices(b) is not None)
    return f"""
  <asset>
    <texture name="tex_checker" type="2d" builtin="checker" rgb1=".83 .83 .81" rgb2=".70 .70 .69" width="256" height="256"/>
    <texture name="tex_speckle" type="2d" builtin="flat" rgb1=".80 .78 .75" mark="random" random="0.08" markrgb=".55 .55 .55" width="512" height="512"/>
    <texture name="tex_gradient" type="2d" builtin="gradient" rgb1=".88 .88 .88" rgb2=".62 .62 .64" width="256" height="256"/>
    <material name="table_grey" rgba=".78 .78 .78 1" specular="0" shininess="0"/>
    <material name="table_checker" texture="tex_checker" texrepeat="8 8" specular="0" shininess="0"/>
    <material name="table_speckle" texture="tex_speckle" texrepeat="2 2" specular="0" shininess="0"/>
    <material name="table_gradient" texture="tex_gradient" specular="0" shininess="0"/>
    <material name="matte" specular="0" shininess="0" reflectance="0"/>
    <material name="metal" specular="0.3" shininess="0.3"/>
    {meshes}
  </asset>"""


@functools.lru_cache(maxsize=1)
def scene_xml() -> str:
    """The whole scene's MJCF text."""
    assert TEXTURES == ("grey", "checker", "speckle", "gradient")
    objects = "\n    ".join(_object_xml(k, b) for k, b in enumerate(BODIES))
    distractors = "\n    ".join(
        f'<body name="distractor{k}" mocap="true" pos="{_fmt([-1.0, -1.0 - 0.3 * k, 0.02])}">'
        f'<geom name="distractor{k}" type="box" size="0.025 0.035 0.02" contype="0" conaffinity="0" '
        f'rgba="0.9 0.9 0.9 1" material="matte"/></body>' for k in range(N_DISTRACTORS))
    r = 0.018 * WORKSPACE_SIDE
    arm_actuators = "\n    ".join(
        f'<position name="{j}" joint="{j}" kp="{3500 if k < 3 else 3000}" kv="{200 if k < 3 else 60}" '
        f'forcerange="{-150 if k < 3 else -28} {150 if k < 3 else 28}"/>' for k, j in enumerate(ARM_JOINTS))
    tx, ty = TABLE_CENTRE
    return f"""<mujoco model="vccjax-tabletop">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="0.005" integrator="implicitfast" solver="Newton" iterations="5" ls_iterations="8"
          cone="pyramidal" impratio="3" gravity="0 0 -9.81"/>
  <visual>
    <global offwidth="640" offheight="640"/>
    <quality shadowsize="0"/>
    <headlight ambient=".45 .45 .45" diffuse=".5 .5 .5" specular="0 0 0"/>
  </visual>
  {_assets()}
  <worldbody>
    <light pos="{tx} {ty} 2.5" dir="0 0 -1" diffuse=".35 .35 .35" specular="0 0 0" castshadow="false"/>
    <geom name="table" type="plane" size="3 3 0.1" contype="{_TABLE}" conaffinity="{_OBJECT}" condim="3"
          friction="0.8 0.005 0.0001" rgba="0 0 0 0"/>
    <geom name="floor" type="plane" size="4 4 0.1" pos="0 0 -0.74" contype="0" conaffinity="0" rgba=".25 .25 .27 1"/>
    <geom name="table_top" type="box" size="{TABLE_HALF[0]} {TABLE_HALF[1]} 0.02" pos="{tx} {ty} -0.02"
          contype="0" conaffinity="0" material="table_grey"/>
    <camera name="top" pos="{_fmt(CAMERA['pos'])}" xyaxes="0 -1 0 1 0 0" fovy="{CAMERA['fovy']}"/>
    <camera name="oblique" pos="1.15 -0.75 0.75" xyaxes="0.7166 0.6975 0 -0.4063 0.4174 0.8128" fovy="45"/>
    <body name="pointer" mocap="true" pos="-1 1 0.0005">
      <geom name="pointer_ring" type="cylinder" size="{r:.5g} 0.0005" contype="0" conaffinity="0" rgba="0.02 0.02 0.02 1" material="matte"/>
      <geom name="pointer_dot" type="cylinder" size="{r / 2:.5g} 0.0006" pos="0 0 0.0002" contype="0" conaffinity="0" rgba="1 1 1 1" material="matte"/>
    </body>
    {distractors}
    {_arm_xml()}
    {objects}
  </worldbody>
  {_excludes()}
  <equality>
    <joint joint1="finger_a" joint2="finger_b" polycoef="0 1 0 0 0" solref="0.005 1"/>
  </equality>
  <tendon>
    <fixed name="grip"><joint joint="finger_a" coef="0.5"/><joint joint="finger_b" coef="0.5"/></fixed>
  </tendon>
  <actuator>
    {arm_actuators}
    <position name="grip" tendon="grip" kp="400" kv="20" ctrlrange="0 {FINGER_OPEN}" forcerange="-40 40"/>
  </actuator>
</mujoco>"""


def _slot(name: str) -> int:
    return [b.name for b in BODIES].index(name)


def _excludes() -> str:
    pairs = "".join(f'<exclude body1="slot{_slot(a)}" body2="slot{_slot(b)}"/>' for a, b in APART)
    return f"<contact>{pairs}</contact>" if pairs else ""


def table_materials() -> dict[str, str]:
    return {t: f"table_{t}" for t in TEXTURES}
