"""Rivals of a reference program: nearby programs a concept's training pairs must rule out.

Ten random pairs often fail to pin a concept down. The 546-concept run on dataset
format 5 found 520 concepts, but 55 of the programs found were wrong on some test
pairs. Each time the found program was simpler than the reference and agreed with it
on every training pair:
- it dropped a filter (no training input held a same-shape object of another colour);
- it moved a single object where the reference loops (each training input held one);
- it did a concept's two parts in the other order (no training object was both green
  and a circle).

The training split is therefore made to tell the reference from every rival listed
here (`pairs.discriminate`): each rival fails, or gives another output, on at
least one training pair. The rivals are simple edits of the reference: one
instruction deleted (but a last `release_object`), each loop run as one or two
straight passes (each loop of the six concepts with two loops in turn, the other left
as written), or the parts between `reset_attn` reordered.
"""

from __future__ import annotations

import itertools

from vccjax.errors import ProgramSyntaxError
from vccjax.machine.instructions import NAMES, OP
from vccjax.machine.program import Program, check_loop_syntax

Rival = tuple[str, Program]  # (what was changed, the program)


def rival_programs(program: Program) -> list[Rival]:
    """Distinct, syntactically valid rivals of `program`, labelled, in a fixed order."""
    steps = list(zip(program.ops, program.args))
    found: dict[tuple, Rival] = {}

    def add(label: str, new_steps: list[tuple[int, int]]) -> None:
        rival = Program(tuple(o for o, _ in new_steps), tuple(a for _, a in new_steps))
        try:
            check_loop_syntax(rival)
        except ProgramSyntaxError:
            return
        key = (rival.ops, rival.args)
        if key not in found and key != (program.ops, program.args):
            found[key] = (label, rival)

    loop_marks = (OP["loop_start"], OP["loop_end"])
    for i in range(1, len(steps)):  # scene_parse (instruction 0) stays
        if i == len(steps) - 1 and steps[i][0] == OP["release_object"]:
            continue  # an output scene does not record the hand: dropping a last release changes nothing
        if steps[i][0] not in loop_marks:
            add(f"without {NAMES[steps[i][0]]} at {i}", steps[:i] + steps[i + 1 :])

    starts = [i for i, (op, _) in enumerate(steps) if op == OP["loop_start"]]
    for n, s in enumerate(starts):  # loops do not nest: each runs to the next loop_end
        e = next(i for i in range(s + 1, len(steps)) if steps[i][0] == OP["loop_end"])
        body = steps[s + 1 : e]
        which = f"loop {n + 1}" if len(starts) > 1 else "loop"
        for passes in (1, 2):
            add(f"{which} as {passes} straight pass{'es' * (passes > 1)}", steps[:s] + body * passes + steps[e + 1 :])

    for label, new_steps in _reordered_parts(steps):
        add(label, new_steps)
    return list(found.values())


def _reordered_parts(steps: list[tuple[int, int]]):
    """Every other order of the parts between top-level `reset_attn`s (after scene_parse)."""
    reset = OP["reset_attn"]
    parts: list[list[tuple[int, int]]] = [[]]
    depth = 0
    for step in steps[1:]:
        depth += step[0] == OP["loop_start"]
        depth -= step[0] == OP["loop_end"]
        if step[0] == reset and depth == 0:
            parts.append([])
        else:
            parts[-1].append(step)
    if len(parts) < 2 or len(parts) > 4:
        return
    for order in itertools.islice(itertools.permutations(range(len(parts))), 1, None):  # all but as written
        joined = list(steps[:1])
        for k, p in enumerate(order):
            joined += ([(reset, 0)] if k else []) + parts[p]
        yield f"parts in order {order}", joined
