""""The square" or "every square": rivals a few pairs often leave open, made from the
program learned rather than searched for.

Pairs whose tables hold one square each are explained as well by "recolour the square"
as by "recolour every square", and the search's rival pass only finds the loop when it
lies within its margin of the first program (it usually costs more: a loop's tokens are
rarer). So the program learned is turned both ways here: its first object-wise part
(from a `top_down_attend` to the next filter change, reset or end) run for every object
in a loop, or a loop's body run once. A variant counts as a rival only where it explains
every pair too, and the ambiguity judge then asks the question that tells them apart.
"""

from __future__ import annotations

from vccjax.errors import ProgramSyntaxError
from vccjax.machine.instructions import FORBIDDEN_IN_LOOP, OP
from vccjax.machine.program import Program, check_loop_syntax

_ENDS_PART = {OP[n] for n in FORBIDDEN_IN_LOOP}  # a part acting on the attended objects ends here
LOOP_START, LOOP_END, ATTEND, NEXT = (OP[n] for n in ("loop_start", "loop_end", "top_down_attend", "next_object"))
GRAB, RELEASE = OP["grab_object"], OP["release_object"]


def for_every_object(program: Program) -> Program | None:
    """The first part from a `top_down_attend` to the next filter change, reset or end,
    run for every attended object: a loop whose body ends with `next_object` (and drops
    what it grabbed first, so the next object can be grabbed). None where the program
    already loops or has no such part."""
    ops, args = list(program.ops), list(program.args)
    if LOOP_START in ops or ATTEND not in ops:
        return None
    i = ops.index(ATTEND)
    j = next((k for k in range(i + 1, len(ops)) if ops[k] in _ENDS_PART), len(ops))
    body_ops, body_args = ops[i:j], args[i:j]
    if NEXT in body_ops:
        return None  # it walks the objects itself
    if GRAB in body_ops and RELEASE not in body_ops[body_ops.index(GRAB):]:
        body_ops, body_args = body_ops + [RELEASE], body_args + [0]
    return _checked(ops[:i] + [LOOP_START] + body_ops + [NEXT, LOOP_END] + ops[j:],
                    args[:i] + [0] + body_args + [0, 0] + args[j:])


def for_the_first_object(program: Program) -> Program | None:
    """A loop's body run once, on the first attended object (its `next_object`s and the
    loop's brackets dropped). None where the program has no loop."""
    ops, args = list(program.ops), list(program.args)
    if LOOP_START not in ops:
        return None
    i = ops.index(LOOP_START)
    j = ops.index(LOOP_END, i)
    keep = [k for k in range(i + 1, j) if ops[k] != NEXT]
    return _checked(ops[:i] + [ops[k] for k in keep] + ops[j + 1:], args[:i] + [args[k] for k in keep] + args[j + 1:])


def variants(program: Program) -> list[Program]:
    """The program's each-or-one variants (none, one, or two), in that order."""
    return [v for v in (for_every_object(program), for_the_first_object(program)) if v is not None]


def _checked(ops: list[int], args: list[int]) -> Program | None:
    try:
        p = Program(tuple(ops), tuple(args))
        check_loop_syntax(p, complete=True)
    except ProgramSyntaxError:
        return None
    return p
