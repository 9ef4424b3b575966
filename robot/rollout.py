"""A concept carried out on the arm, for a batch of randomized scenarios.

Per scenario: dress the scene and capture the camera image (C MuJoCo renderer), parse
it, run the program on the parsed scene (reference interpreter), turn its hand
instructions into keyframes; then every scenario's rollout runs at once under
`jax.vmap` on MJX; finally each is judged against the VCC's output.
"""

from __future__ import annotations

import dataclasses
import time

import jax
import jax.numpy as jnp
import mujoco
import numpy as np

from robot.camera import Camera
from robot.control import RECORD, TICK, Arm, Keyframes
from robot.judge import Verdict, judge
from robot.mjcf import scene_xml
from robot.motion import keyframes
from robot.plan import PickPlace, PlanError, plan
from robot.scenario import Scenario, draw
from robot.truth import ParseCheck, check_parse
from vccjax.errors import SceneError
from vccjax.machine.program import Program
from vccjax.machine.scene import Scene



@dataclasses.dataclass
class Prepared:
    scenario: Scenario
    parsed: Scene | None
    moves: list[PickPlace]
    expected: Scene | None  # the VCC's output on the parsed scene
    keyframes: Keyframes | None
    ticks: int
    error: str | None  # "parse error: ...", "parse wrong: ..." or "plan error: ..."
    windows: list[tuple[int, int]] = dataclasses.field(default_factory=list)  # per move: ticks held aloft
    check: ParseCheck | None = None  # the parse against the true scene


class Bench:
    """The compiled model, its renderer and its jitted rollout, made once."""

    def __init__(self):
        self.model = mujoco.MjModel.from_xml_string(scene_xml())
        self.data = mujoco.MjData(self.model)
        self.arm = Arm(self.model)
        self._camera: Camera | None = None

    @property
    def camera(self) -> Camera:
        if self._camera is None:
            self._camera = Camera(self.model)
        return self._camera

    def prepare(self, program: Program | list[Program], scenario: Scenario) -> Prepared:
        m, d = self.model, self.data
        d.qpos[:] = scenario.qpos(m)
        scenario.dress(m, d)
        mujoco.mj_forward(m, d)
        start = d.site("tcp").xpos.copy()
        x_axis = d.site("tcp").xmat.reshape(3, 3)[:, 0]
        start_yaw = float(np.arctan2(x_axis[1], x_axis[0]))
        try:
            parsed, _ = self.camera.scene(d)
        except SceneError as e:
            return Prepared(scenario, None, [], None, None, 0, f"parse error: {e}")
        check = check_parse(scenario.scene, parsed)
        if not check.exact:  # the arm would act on a scene that is not on the table
            return Prepared(scenario, parsed, [], None, None, 0, f"parse wrong: {check.problem()}", check=check)
        try:
            moves, expected = plan(program, parsed)
            if [o.color for o in expected.objects] != [o.color for o in parsed.objects]:
                raise PlanError("the program changes a colour, which the arm cannot")
            kf, ticks, windows = keyframes(moves, start, start_yaw)
        except (PlanError, ValueError) as e:
            return Prepared(scenario, parsed, [], None, None, 0, f"plan error: {e}", check=check)
        return Prepared(scenario, parsed, moves, expected, kf, ticks, None, windows, check)

    def run(self, program: Program | list[Program], scenarios: list[Scenario], keep: bool = False
            ) -> tuple[list[Verdict], dict, list[np.ndarray | None]]:
        """Prepare, roll out (one batch) and judge; returns verdicts, timings, and (with
        `keep`) each scenario's recorded qpos."""
        return self.run_pairs([(program, s) for s in scenarios], keep)

    def run_pairs(self, items: list[tuple[Program | list[Program], Scenario]], keep: bool = False,
                  pad_to: int | None = None) -> tuple[list[Verdict], dict, list[np.ndarray | None]]:
        """As `run`, each scenario with its own program. With `pad_to`, the batch rolled out
        is always that size (the last live scenario repeated, its copies thrown away): MJX
        compiles once per batch size, and a few scenarios refused by the parse or the plan
        would otherwise cost a compilation of minutes."""
        t0 = time.perf_counter()
        prepared = [self.prepare(program, s) for program, s in items]
        t_prep = time.perf_counter() - t0
        live = [p for p in prepared if p.error is None]
        records: dict[int, np.ndarray] = {}
        t_compile = t_run = 0.0
        ticks = 0
        if live:
            ticks = max(p.ticks for p in live) + 25
            rows = live + [live[-1]] * max(0, (pad_to or 0) - len(live))
            q0 = jnp.asarray(np.stack([p.scenario.qpos(self.model) for p in rows]))
            kf = jax.tree.map(lambda *x: jnp.asarray(np.stack(x)), *[p.keyframes for p in rows])
            t1 = time.perf_counter()
            self.arm.compile(q0, kf)  # apart from the run (cached per batch size)
            t_compile = time.perf_counter() - t1
            t2 = time.perf_counter()
            qs = self.arm.rollout(q0, kf, ticks)
            t_run = time.perf_counter() - t2
            ticks = qs.shape[1] * RECORD
            for k, p in enumerate(live):
                records[id(p)] = qs[k]
        verdicts = [judge(self.model, p, records.get(id(p))) for p in prepared]
        kept = [records.get(id(p)) for p in prepared] if keep else []
        return verdicts, {"prepare_s": t_prep, "compile_s": t_compile, "rollout_s": t_run, "ticks": ticks,
                          "simulated_s": ticks * TICK, "scenarios": len(items)}, kept


def scenarios_for(program: Program | list[Program], n: int, seed: int = 0) -> list[Scenario]:
    return [draw(program, seed * 100_003 + k) for k in range(n)]
