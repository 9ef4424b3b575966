"""The same controller on C MuJoCo, one scenario at a time, in plain NumPy.

It is the oracle the batched MJX rollout is tested against (as the scalar interpreter
is for the JAX emulator), and a fast way to look at one scenario: C MuJoCo steps
this scene some 10x faster than one MJX environment on this CPU.
"""

from __future__ import annotations

import mujoco
import numpy as np

from robot.control import DAMPING, MAX_STEP, MAX_TURN, SUBSTEPS, Keyframes
from robot.mjcf import ARM_JOINTS


def target_at(kf: Keyframes, t: int) -> tuple[np.ndarray, float, float]:
    tick = np.asarray(kf.tick)
    k = int(np.clip(np.searchsorted(tick, t, side="left"), 1, len(tick) - 1))
    t0, t1 = tick[k - 1], tick[k]
    a = 1.0 if t >= t1 else float(np.clip((t - t0) / max(t1 - t0, 1), 0.0, 1.0))
    pos = np.asarray(kf.pos)
    yaw = np.asarray(kf.yaw)
    return pos[k - 1] + a * (pos[k] - pos[k - 1]), float(yaw[k - 1] + a * (yaw[k] - yaw[k - 1])), float(kf.grip[k])


def rollout(model: mujoco.MjModel, qpos0: np.ndarray, kf: Keyframes, ticks: int,
            record_every: int = 1) -> np.ndarray:
    """qpos every `record_every` ticks: (ticks // record_every, nq)."""
    d = mujoco.MjData(model)
    d.qpos[:] = qpos0
    arm_q = np.array([model.joint(j).qposadr[0] for j in ARM_JOINTS])
    arm_v = np.array([model.joint(j).dofadr[0] for j in ARM_JOINTS])
    arm_a = np.array([model.actuator(j).id for j in ARM_JOINTS])
    grip_a, tcp, body = model.actuator("grip").id, model.site("tcp").id, model.body("gripper").id
    d.ctrl[arm_a] = qpos0[arm_q]
    mujoco.mj_forward(model, d)
    jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    out = []
    for t in range(ticks // record_every * record_every):
        pos, yaw, grip = target_at(kf, t)
        p, r = d.site_xpos[tcp].copy(), d.site_xmat[tcp].reshape(3, 3)
        x_goal = np.array([np.cos(yaw), np.sin(yaw), 0.0])
        z_goal = np.array([0.0, 0.0, -1.0])
        goal = np.stack([x_goal, np.cross(z_goal, x_goal), z_goal], axis=1)
        e_pos = pos - p
        e_pos *= min(1.0, MAX_STEP / (np.linalg.norm(e_pos) + 1e-9))
        e_rot = 0.5 * sum(np.cross(r[:, i], goal[:, i]) for i in range(3))
        e_rot *= min(1.0, MAX_TURN / (np.linalg.norm(e_rot) + 1e-9))
        mujoco.mj_jac(model, d, jacp, jacr, p, body)
        jac = np.concatenate([jacp[:, arm_v], jacr[:, arm_v]])
        dq = jac.T @ np.linalg.solve(jac @ jac.T + DAMPING**2 * np.eye(6), np.concatenate([e_pos, e_rot]))
        d.ctrl[arm_a] = d.qpos[arm_q] + dq
        d.ctrl[grip_a] = grip
        for _ in range(SUBSTEPS):
            mujoco.mj_step(model, d)
        if (t + 1) % record_every == 0:
            out.append(d.qpos.copy())
    return np.array(out)
