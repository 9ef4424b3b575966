"""The arm's Cartesian controller and batched rollouts on MJX.

Each scenario's motion is a table of keyframes (tool-centre target, gripper yaw, finger
command, the control tick at which it is reached); between keyframes the target moves
in a straight line. Every control tick (50 Hz) a damped-least-squares step of
differential inverse kinematics (the Jacobian from `mjx.jac`) turns the pose error into
joint targets for the arm's position servos. Keyframe tables of every scenario share
one shape, so one compiled rollout serves every concept.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
from flax import struct
from mujoco import mjx

from robot.mjcf import ARM_JOINTS

SUBSTEPS = 4  # physics steps (5 ms) per control tick: 50 Hz
TICK = 0.02  # seconds
MAX_STEP = 0.02  # metres of Cartesian error acted on per tick
MAX_TURN = 0.15  # radians of orientation error acted on per tick
DAMPING = 0.05  # of the least-squares step
RECORD = 5  # ticks between recorded states (10 Hz)
CHUNK = 250  # ticks per compiled piece of rollout (5 s)


@struct.dataclass
class Keyframes:
    """(K,) or (B, K) arrays; keyframe 0 is the start, reached at tick 0."""

    tick: jax.Array  # int32, non-decreasing: when the target reaches keyframe k
    pos: jax.Array  # (K, 3) tool-centre target in the world
    yaw: jax.Array  # (K,) finger axis angle from world +x
    grip: jax.Array  # (K,) finger opening command (m per finger) from keyframe k-1 to k


def target_at(kf: Keyframes, t: jax.Array) -> tuple[jax.Array, jax.Array, jax.Array]:
    """Target (pos, yaw, grip) at tick t: linear between keyframes, held after the last."""
    k = jnp.clip(jnp.searchsorted(kf.tick, t, side="left"), 1, kf.tick.shape[0] - 1)
    t0, t1 = kf.tick[k - 1], kf.tick[k]
    a = jnp.clip((t - t0) / jnp.maximum(t1 - t0, 1), 0.0, 1.0)
    a = jnp.where(t >= t1, 1.0, a)
    pos = kf.pos[k - 1] + a * (kf.pos[k] - kf.pos[k - 1])
    yaw = kf.yaw[k - 1] + a * (kf.yaw[k] - kf.yaw[k - 1])
    return pos, yaw, kf.grip[k]


class Arm:
    """Indices into one compiled model, and the jitted pieces that use it."""

    def __init__(self, model: mujoco.MjModel):
        self.model = model
        self.mx = mjx.put_model(model)
        self.arm_qpos = np.array([model.joint(j).qposadr[0] for j in ARM_JOINTS])
        self.arm_dof = np.array([model.joint(j).dofadr[0] for j in ARM_JOINTS])
        self.tcp = model.site("tcp").id
        self.gripper_body = model.body("gripper").id
        self.grip_act = model.actuator("grip").id
        self.arm_act = np.array([model.actuator(j).id for j in ARM_JOINTS])
        self._compiled: dict = {}
        self.start = jax.jit(self._start)
        self.advance = jax.jit(self._advance)

    def ctrl(self, d: mjx.Data, pos: jax.Array, yaw: jax.Array, grip: jax.Array) -> jax.Array:
        """One tick of damped-least-squares differential IK: joint targets for the servos."""
        p = d.site_xpos[self.tcp]
        r = d.site_xmat[self.tcp]
        x_goal = jnp.array([jnp.cos(yaw), jnp.sin(yaw), 0.0])
        z_goal = jnp.array([0.0, 0.0, -1.0])
        goal = jnp.stack([x_goal, jnp.cross(z_goal, x_goal), z_goal], axis=1)
        e_pos = pos - p
        e_pos = e_pos * jnp.minimum(1.0, MAX_STEP / (jnp.linalg.norm(e_pos) + 1e-9))
        e_rot = 0.5 * sum(jnp.cross(r[:, i], goal[:, i]) for i in range(3))
        e_rot = e_rot * jnp.minimum(1.0, MAX_TURN / (jnp.linalg.norm(e_rot) + 1e-9))
        jacp, jacr = mjx.jac(self.mx, d, p, self.gripper_body)
        jac = jnp.concatenate([jacp[self.arm_dof].T, jacr[self.arm_dof].T])  # (6, 6)
        err = jnp.concatenate([e_pos, e_rot])
        dq = jac.T @ jnp.linalg.solve(jac @ jac.T + DAMPING**2 * jnp.eye(6), err)
        q = d.qpos[self.arm_qpos] + dq
        ctrl = d.ctrl.at[self.arm_act].set(q)
        return ctrl.at[self.grip_act].set(grip)

    def _start(self, qpos0: jax.Array) -> mjx.Data:
        """Batched initial states: qpos0 (B, nq), servos holding the arm where it is."""

        def one(q0):
            d = mjx.make_data(self.mx).replace(qpos=q0)
            d = d.replace(ctrl=d.ctrl.at[self.arm_act].set(q0[self.arm_qpos]))
            return mjx.forward(self.mx, d)

        return jax.vmap(one)(qpos0)

    def _advance(self, d: mjx.Data, kf: Keyframes, t0: jax.Array) -> tuple[mjx.Data, jax.Array]:
        """CHUNK control ticks from tick t0 for a batch; qpos every RECORD ticks. Every
        concept's rollout is a number of these chunks, so one compilation serves all (per
        batch size). The model is closed over (passing it costs ~40 ms a call)."""

        def one(d, kf1):
            def tick(d, t):
                pos, yaw, grip = target_at(kf1, t)
                d = d.replace(ctrl=self.ctrl(d, pos, yaw, grip))
                d = jax.lax.fori_loop(0, SUBSTEPS, lambda _, x: mjx.step(self.mx, x), d)
                return d, None

            def record(d, t):
                d, _ = jax.lax.scan(tick, d, t + jnp.arange(RECORD))
                return d, d.qpos

            return jax.lax.scan(record, d, t0 + jnp.arange(CHUNK // RECORD) * RECORD)

        return jax.vmap(one)(d, kf)

    def compile(self, qpos0: jax.Array, kf: Keyframes):
        """Both pieces compiled for this batch's shapes (kept per batch size), so that a
        rollout's timing keeps compilation apart."""
        key = (qpos0.shape, kf.tick.shape)
        if key not in self._compiled:
            d = jax.eval_shape(self.start, qpos0)
            self._compiled[key] = (self.start.lower(qpos0).compile(),
                                   self.advance.lower(d, kf, jnp.int32(0)).compile())
        return self._compiled[key]

    def rollout(self, qpos0: jax.Array, kf: Keyframes, ticks: int) -> np.ndarray:
        """qpos (B, ceil(ticks / CHUNK) * CHUNK / RECORD, nq), recorded every RECORD ticks."""
        start, advance = self.compile(qpos0, kf)
        d = start(qpos0)
        out = []
        for t0 in range(0, ticks, CHUNK):
            d, qs = advance(d, kf, jnp.int32(t0))
            out.append(np.asarray(qs))
        return np.concatenate(out, axis=1)
