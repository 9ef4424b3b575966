"""Which concepts the arm's suite runs: those an arm can carry out, and by default a
stated, stratified choice of them.

A program is arm-able when it grabs something and does nothing a hand cannot: no
recolouring or removal (`robot.plan.NOT_ON_A_ROBOT`), no imagined objects (they would
block carries), and no attention to a shape none of the arm's bodies has
(`robot.world.BODIES`: every VCC shape has one).

The default choice stratifies by program length (instructions, loops counted once as
written), because length is what makes a concept hard for the arm (more carries, more
chances to drop or misplace): a stratum of at most `WHOLE` concepts is taken whole, and
the other strata share the rest of `count` in proportion to their sizes, each a seeded
sample (if the small strata alone exceed `count`, all strata share it). The choice is
seeded apart from the scenarios, so every suite picks the same concepts. With the run of
record this takes every concept of 9 to 12 and of 16 or more instructions, and samples
the large strata of short programs and of 13, 14 and 15.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from vccjax.machine.instructions import NAMES, SHAPES
from vccjax.machine.program import Program

STRATA: tuple[tuple[int, int], ...] = ((1, 8), (9, 12), (13, 13), (14, 14), (15, 15), (16, 10**6))
WHOLE = 40  # a stratum this small is run whole
COUNT = 150  # concepts in the default choice


def not_arm_able(program: Program | list[Program]) -> str | None:
    """Why the arm cannot carry `program` out (None when it can)."""
    from robot.plan import NOT_ON_A_ROBOT
    from robot.world import BODIES

    programs = program if isinstance(program, list) else [program]
    used = {NAMES[op] for p in programs for op in p.ops}
    for name, why in NOT_ON_A_ROBOT.items():
        if name in used:
            return why
    if used & {"imagine_object", "reset_imagination"}:
        return "imagines objects"
    if "grab_object" not in used:
        return "grabs nothing"
    shapes = {s for b in BODIES for s in b.shapes}
    for p in programs:
        for op, arg in zip(p.ops, p.args, strict=True):
            if NAMES[op] == "set_shape_attn" and SHAPES[arg] not in shapes:
                return f"attends to {SHAPES[arg]}s, and no body on the table is one"
    return None


def arm_able(programs: Mapping[str, Program]) -> list[str]:
    """The names whose program the arm can carry out, in the mapping's order."""
    return [c for c, p in programs.items() if not_arm_able(p) is None]


def length(program: Program | list[Program]) -> int:
    programs = program if isinstance(program, list) else [program]
    return sum(len(p.ops) for p in programs)


def default_choice(programs: Mapping[str, Program], count: int = COUNT, seed: int = 0) -> list[str]:
    """`count` arm-able concepts, stratified by length (module docstring), sorted by name."""
    able = sorted(arm_able(programs))
    strata = [[c for c in able if lo <= length(programs[c]) <= hi] for lo, hi in STRATA]
    whole = [s for s in strata if len(s) <= WHOLE]
    rest = [s for s in strata if len(s) > WHOLE]
    if sum(len(s) for s in whole) > count:  # a small count: every stratum shares it
        whole, rest = [], [s for s in strata if s]
    left = max(count - sum(len(s) for s in whole), 0)
    total = sum(len(s) for s in rest)
    # largest remainder: each sampled stratum gets its share of what is left, rounded fairly
    shares = np.array([left * len(s) / total for s in rest]) if total else np.zeros(0)
    take = np.floor(shares).astype(int)
    for k in np.argsort(-(shares - take), kind="stable")[: left - int(take.sum())]:
        take[k] += 1
    rng = np.random.default_rng([seed, 0xC401])
    chosen = [c for s in whole for c in s]
    for s, n in zip(rest, take, strict=True):
        chosen += [s[int(i)] for i in sorted(rng.choice(len(s), min(int(n), len(s)), replace=False))]
    return sorted(chosen)
