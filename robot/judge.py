"""Did a rollout carry the concept out? And if not, why.

Success: every object's final position on the table is within `TOLERANCE` of where the
VCC's output puts it (through the workspace-to-table mapping), nothing fell off the
table, and at the end the gripper is open and clear of every object. The VCC's output
is computed on the parsed scene, and the parse is first checked against the scene truly
on the table (`robot.truth`): every true object seen once, shape, colour and centre
right, so each true object's goal is known. A failure is put down to the first cause
that holds, in this order: no scenario (none of the arm's bodies can stage the concept),
parse error (nothing could be parsed), parse wrong, plan error, non-finite state, IK
unreachable (the tool never got within 2 cm of a target), object fell off the table,
grasp slipped (a carried object was never lifted, or lagged the tool by 2 cm while
carried), object dropped (lifted, then fell before its place), gripper not clear,
misplaced.
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np

from robot.control import RECORD, TICK
from robot.world import BODIES, on_table, to_table

TOLERANCE = 0.02
CAUSES = ("no scenario", "parse error", "parse wrong", "plan error", "non-finite state", "IK unreachable", "fell off the table", "grasp slipped", "object dropped",
          "gripper not clear", "misplaced")


@dataclasses.dataclass(frozen=True)
class Verdict:
    success: bool
    cause: str | None  # one of CAUSES when not a success
    detail: str
    max_error_m: float  # largest final distance of an object from its VCC place (nan if not run)
    seed: int
    parse: dict | None = None  # the parse against the truth (`robot.truth.ParseCheck.record`), when parsed

    def record(self) -> dict:
        """The verdict as strict JSON: a placement error not measured (nan) is null."""
        return {k: (None if isinstance(v, float) and v != v else v) for k, v in self.__dict__.items()}


def _slot_xyz(model: mujoco.MjModel, q: np.ndarray) -> np.ndarray:
    """(..., slots, 3) body positions from recorded qpos (..., nq)."""
    adr = np.array([model.joint(f"slot{k}").qposadr[0] for k in range(len(BODIES))])
    return np.stack([q[..., a:a + 3] for a in adr], -2)


def _tcp(model: mujoco.MjModel, qs: np.ndarray) -> np.ndarray:
    d = mujoco.MjData(model)
    out = np.empty((len(qs), 3))
    for t, q in enumerate(qs):
        d.qpos[:] = q
        mujoco.mj_kinematics(model, d)
        out[t] = d.site("tcp").xpos
    return out


def judge(model: mujoco.MjModel, prepared, qs: np.ndarray | None) -> Verdict:
    """The verdict on one prepared scenario, with its parse's record."""
    v = _verdict(model, prepared, qs)
    return dataclasses.replace(v, parse=prepared.check.record() if prepared.check is not None else None)


def _verdict(model: mujoco.MjModel, prepared, qs: np.ndarray | None) -> Verdict:
    seed = prepared.scenario.seed
    if prepared.error is not None:
        cause = prepared.error.split(":")[0]
        return Verdict(False, cause, prepared.error, float("nan"), seed)
    if qs is None or not np.isfinite(qs).all():  # NaN compares false: it would pass every check below
        return Verdict(False, "non-finite state", "the rollout's state is not finite", float("nan"), seed)
    sc, expected = prepared.scenario, prepared.expected
    # each parsed object is the true object it was matched to (the parse was checked exact,
    # so every true object has one), and its goal is the program's output for it
    slot_of = [sc.slots[j] for j in prepared.check.match]
    xyz = _slot_xyz(model, qs)  # (T, slots, 3)
    final = xyz[-1]
    goal = np.array([to_table(o.x, o.y) for o in expected.objects])
    err = np.array([np.linalg.norm(final[k, :2] - g) for k, g in zip(slot_of, goal)])
    worst = float(err.max()) if len(err) else 0.0
    tcp = _tcp(model, qs)
    kf = prepared.keyframes
    ticks = np.arange(1, len(qs) + 1) * RECORD
    reached = [np.min(np.linalg.norm(tcp - kf.pos[i], axis=1)) for i in range(len(kf.tick)) if kf.tick[i] <= ticks[-1]]
    if max(reached) > 0.02:
        return Verdict(False, "IK unreachable", f"a target stayed {max(reached) * 100:.1f} cm away", worst, seed)
    placed = [k for k in sc.slots]
    off = [k for k in placed if not on_table(final[k, 0], final[k, 1]) or final[k, 2] < -0.01]
    if off:
        return Verdict(False, "fell off the table", f"slots {off}", worst, seed)
    for mv, (aloft, lowering) in zip(prepared.moves, prepared.windows):
        k = slot_of[mv.slot]
        window = (ticks >= aloft) & (ticks <= lowering)
        if not window.any():
            continue
        z = xyz[window, k, 2]
        rest = BODIES[k].height / 2
        if z[0] < rest + 0.008:
            return Verdict(False, "grasp slipped", f"{BODIES[k].name} was not lifted", worst, seed)
        if (z < rest + 0.004).any():
            t = (aloft + np.argmax(z < rest + 0.004) * RECORD) * TICK
            return Verdict(False, "object dropped", f"{BODIES[k].name} fell at {t:.1f} s", worst, seed)
        lag = np.linalg.norm(xyz[window, k, :2] - tcp[window, :2], axis=1).max()
        if lag > 0.02:
            return Verdict(False, "grasp slipped", f"{BODIES[k].name} lagged the tool by {lag * 100:.1f} cm",
                           worst, seed)
    d = mujoco.MjData(model)
    d.qpos[:] = qs[-1]
    mujoco.mj_forward(model, d)
    opening = d.joint("finger_a").qpos[0]
    pads = {model.geom("pad_a").id, model.geom("pad_b").id}
    touching = any({int(c.geom1), int(c.geom2)} & pads for c in d.contact[: d.ncon])
    top = max(final[k, 2] - BODIES[k].height / 2 + BODIES[k].top for k in placed)
    if opening < 0.8 * float(kf.grip[-1]) or touching or tcp[-1, 2] - 0.015 < top + 0.01:
        return Verdict(False, "gripper not clear", f"opening {opening * 100:.1f} cm, tool at {tcp[-1, 2]:.3f} m"
                       + (", a pad touches an object" if touching else ""), worst, seed)
    if worst > TOLERANCE:
        return Verdict(False, "misplaced", f"an object ended {worst * 100:.1f} cm from its place", worst, seed)
    return Verdict(True, None, f"largest error {worst * 100:.1f} cm", worst, seed)


def tally(verdicts: list[Verdict]) -> dict:
    """Successes, failures by cause, and every verdict: what a result file keeps."""
    from collections import Counter

    return {"success": sum(v.success for v in verdicts),
            "failures": dict(Counter(v.cause for v in verdicts if not v.success)),
            "verdicts": [v.record() for v in verdicts]}
