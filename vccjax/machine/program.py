"""Programs: the typed form (op indices + argument indices), the text form, and subroutines."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable, Mapping, Sequence

import numpy as np

from vccjax.errors import ProgramSyntaxError
from vccjax.machine.instructions import (
    FORBIDDEN_IN_LOOP,
    NAMES,
    OP,
    REQUIRED_IN_LOOP,
    arg_domain,
)

Step = tuple[str, "str | None"]


@dataclasses.dataclass(frozen=True)
class Program:
    """An atomic program: parallel tuples of op indices and argument indices (0 when none)."""

    ops: tuple[int, ...]
    args: tuple[int, ...]

    def __post_init__(self) -> None:
        if len(self.ops) != len(self.args):
            raise ProgramSyntaxError("ops and args differ in length")
        for i, (op, arg) in enumerate(zip(self.ops, self.args)):
            if not 0 <= op < len(NAMES):
                raise ProgramSyntaxError(f"instruction {i}: unknown op index {op}")
            n = len(arg_domain(NAMES[op]))
            if (n == 0 and arg != 0) or (n > 0 and not 0 <= arg < n):
                raise ProgramSyntaxError(
                    f"instruction {i} ({NAMES[op]}): argument index {arg} out of domain"
                )

    def __len__(self) -> int:
        return len(self.ops)

    @classmethod
    def from_steps(cls, steps: Iterable[Sequence]) -> Program:
        """From (name, arg-or-None) pairs, as in concepts.json."""
        ops, args = [], []
        for i, step in enumerate(steps):
            if len(step) != 2:
                raise ProgramSyntaxError(f"instruction {i}: expected [name, arg], got {step!r}")
            name, arg = step
            op, a = _resolve(name, [] if arg is None else [arg], i)
            ops.append(op)
            args.append(a)
        return cls(tuple(ops), tuple(args))

    def steps(self) -> list[Step]:
        out: list[Step] = []
        for op, arg in zip(self.ops, self.args):
            name = NAMES[op]
            dom = arg_domain(name)
            out.append((name, dom[arg] if dom else None))
        return out

    def text(self, sep: str = "; ") -> str:
        return sep.join(n if a is None else f"{n}({a})" for n, a in self.steps())

    def __str__(self) -> str:
        return self.text()

    def arrays(self, length: int | None = None) -> tuple[np.ndarray, np.ndarray, int]:
        """Padded int32 arrays for the emulator (pad op = -1) and the true length."""
        n = len(self.ops)
        length = n if length is None else length
        if n > length:
            raise ProgramSyntaxError(f"program of {n} instructions exceeds the padded length {length}")
        ops = np.full(length, -1, np.int32)
        args = np.zeros(length, np.int32)
        ops[:n] = self.ops
        args[:n] = self.args
        return ops, args, n


@dataclasses.dataclass(frozen=True)
class Subroutine:
    """A named instruction sequence; its arguments are those of its atoms, in order."""

    name: str
    body: tuple[str, ...]

    def atoms(self, library: Mapping[str, Subroutine]) -> list[str]:
        return _atoms(self.name, library, 0)

    def n_args(self, library: Mapping[str, Subroutine]) -> int:
        return sum(1 for a in self.atoms(library) if arg_domain(a))


def _atoms(name: str, library: Mapping[str, Subroutine], depth: int) -> list[str]:
    """The atomic instructions a name stands for (itself, or a subroutine's expansion)."""
    if name in OP:
        return [name]
    if name not in library:
        raise ProgramSyntaxError(f"unknown instruction or subroutine {name!r}")
    if depth > 32:
        raise ProgramSyntaxError(f"subroutine {name} nests more than 32 deep (a cycle?)")
    return [a for item in library[name].body for a in _atoms(item, library, depth + 1)]


def _resolve(name: str, args: list[str], where: int) -> tuple[int, int]:
    if name not in OP:
        raise ProgramSyntaxError(f"instruction {where}: unknown instruction {name!r}")
    dom = arg_domain(name)
    if not dom:
        if args:
            raise ProgramSyntaxError(f"instruction {where}: {name} takes no argument, got {args}")
        return OP[name], 0
    if len(args) != 1:
        raise ProgramSyntaxError(
            f"instruction {where}: {name} takes one argument of {list(dom)}, got {len(args)}"
        )
    if args[0] not in dom:
        raise ProgramSyntaxError(
            f"instruction {where}: {name}({args[0]}): argument must be one of {list(dom)}"
        )
    return OP[name], dom.index(args[0])


def expand(
    items: Sequence[tuple[str, Sequence[str]]],
    library: Mapping[str, Subroutine] | None = None,
) -> Program:
    """Expand (name, args) items, where a name may be a subroutine, into an atomic program."""
    library = library or {}
    ops: list[int] = []
    out_args: list[int] = []
    for i, (name, args) in enumerate(items):
        if name in OP:
            op, a = _resolve(name, list(args), i)
            ops.append(op)
            out_args.append(a)
            continue
        try:
            atoms = _atoms(name, library, 0)
        except ProgramSyntaxError as e:
            raise ProgramSyntaxError(f"instruction {i}: {e}") from None
        need = sum(1 for a in atoms if arg_domain(a))
        if len(args) != need:
            raise ProgramSyntaxError(
                f"instruction {i}: subroutine {name} takes {need} argument(s), got {len(args)}"
            )
        it = iter(args)
        for atom in atoms:
            op, a = _resolve(atom, [next(it)] if arg_domain(atom) else [], i)
            ops.append(op)
            out_args.append(a)
    return Program(tuple(ops), tuple(out_args))


_ITEM = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\((.*)\))?\s*$")


def parse(
    text: str,
    library: Mapping[str, Subroutine] | None = None,
    *,
    check_loops: bool = True,
    body_max: int | None = None,
) -> Program:
    """Parse the text form of docs/vcc.md section 6 (';' or newline separated, `name` or `name(arg)`).

    Lines starting with '#' are comments. Errors name the instruction's position, and in
    a text of several lines (a program file) its line too.
    """
    items: list[tuple[str, list[str]]] = []
    lines: list[int] = []  # each item's line, from 1
    chunks = [(n, c) for n, line in enumerate(text.removeprefix("\ufeff").splitlines(), 1)
              if not line.strip().startswith("#") for c in line.split(";")]
    try:
        for n, raw in chunks:
            if not raw.strip():
                continue
            lines.append(n)
            m = _ITEM.match(raw)
            if not m:
                raise ProgramSyntaxError(f"instruction {len(items)}: cannot parse {raw.strip()!r}")
            name, argtext = m.group(1), m.group(2)
            args = [] if argtext is None else [a.strip() for a in argtext.split(",")]
            if args == [""]:
                args = []
            if any(not a for a in args):
                raise ProgramSyntaxError(f"instruction {len(items)}: empty argument in {raw.strip()!r}")
            items.append((name, args))
        if not items:
            raise ProgramSyntaxError("empty program")
        program = expand(items, library)
        if check_loops:
            check_loop_syntax(program, complete=True, body_max=body_max)
    except ProgramSyntaxError as e:
        raise ProgramSyntaxError(_with_line(str(e), lines if "\n" in text.strip() and not library else [])) from None
    return program


def _with_line(message: str, lines: Sequence[int]) -> str:
    """"instruction K: ..." as "instruction K (line N): ..." where the K-th item's line is
    known (a subroutine's atoms are not items, so a library's programs keep K alone)."""
    m = re.match(r"instruction (\d+):", message)
    if m is None or int(m.group(1)) >= len(lines):
        return message
    return f"instruction {m.group(1)} (line {lines[int(m.group(1))]}):{message[m.end():]}"


def check_loop_syntax(program: Program, *, complete: bool = True, body_max: int | None = None) -> None:
    """Raise ProgramSyntaxError for loop-structure errors (docs/vcc.md section 5).

    With complete=False an open loop at the end is allowed (a search prefix).
    """
    start = None
    for i, op in enumerate(program.ops):
        name = NAMES[op]
        if start is not None and name in FORBIDDEN_IN_LOOP:
            what = "nested loop_start" if name == "loop_start" else f"{name} inside a loop body"
            raise ProgramSyntaxError(f"instruction {i}: {what} (loop opened at {start})")
        if name == "loop_start":
            start = i
        elif name == "loop_end":
            if start is None:
                raise ProgramSyntaxError(f"instruction {i}: loop_end without loop_start")
            body = {NAMES[o] for o in program.ops[start + 1 : i]}
            missing = sorted(REQUIRED_IN_LOOP - body)
            if missing:
                raise ProgramSyntaxError(
                    f"instruction {i}: loop body ({start + 1}..{i - 1}) lacks {', '.join(missing)}"
                )
            if body_max is not None and i - start - 1 > body_max:
                raise ProgramSyntaxError(
                    f"instruction {i}: loop body of {i - start - 1} exceeds body_max={body_max}"
                )
            start = None
    if complete and start is not None:
        raise ProgramSyntaxError(f"instruction {start}: loop_start without loop_end")
