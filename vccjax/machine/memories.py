"""The machine's five working memories: one vocabulary for both machines.

The JAX emulator (`state.VCCState`) and the reference interpreter (`reference.RefMachine`)
hold the same memories under the same class and field names: here the reference's, in
plain Python; in `state.py` the JAX ones, as fixed-shape arrays. "Nothing" in a slot
register (held, attended, a filter, the failing index, no imagined object) is -1 in both.
Where JAX pads an array, the field names its sibling length field (`padded`); the
reference keeps a plain list and no length.

- blackboard: whether the scene is parsed; per object slot (n_max of them, the scene's
  objects first) alive, colour and whole-pixel offset (x, y) from its centre at load;
  the imagined object's kind (0 circle, 1 hline) and position.
- fovea: position, fixation history, index h into it.
- attention: shape and colour filters, the attended list A, whether A is stale,
  cursor k into A, the attended object.
- hand: position, held object.
- control: failed, failing instruction's program index, program counter, in a loop,
  the loop runs at least once, the recorded loop body (ops, args, program index of its
  first instruction).

`memories(machine)` reads either machine's memories as nested dicts of plain Python
values, the same way for both, so that two machines compare with `==` and
`first_difference` names where they part.
"""

from __future__ import annotations

import dataclasses

import numpy as np

MEMORIES = ("blackboard", "fovea", "attention", "hand", "control")
Point = tuple[int, int]


def padded(length: str):
    """A padded array field (JAX): only its first `length` entries (a sibling field) count."""
    return dataclasses.field(metadata={"length": length})


@dataclasses.dataclass
class Blackboard:
    parsed: bool
    alive: list[bool]
    color: list[int]
    offset: list[Point]  # whole pixels since load
    imagined_kind: int  # -1 none, 0 circle, 1 hline
    imagined_position: Point


@dataclasses.dataclass
class Fovea:
    position: Point
    history: list[Point]
    history_index: int  # h


@dataclasses.dataclass
class Attention:
    shape_filter: int
    color_filter: int
    attended_list: list[int]  # A
    stale: bool
    cursor: int  # k
    attended: int


@dataclasses.dataclass
class Hand:
    position: Point
    held: int


@dataclasses.dataclass
class Control:
    failed: bool
    fail_index: int
    pc: int
    in_loop: bool
    loop_active: bool
    body_ops: list[int]
    body_args: list[int]
    body_pc0: int


def copied(memory):
    """A copy of a (reference) memory whose lists are its own."""
    new = object.__new__(type(memory))
    new.__dict__.update({name: v.copy() if type(v) is list else v for name, v in vars(memory).items()})
    return new


def plain(x):
    """A memory (or any value in one) as plain Python: dataclasses as dicts, arrays and
    tuples as lists; a padded field cut to its length, the length field itself left out."""
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        fields = dataclasses.fields(x)
        lengths = {f.metadata["length"] for f in fields if "length" in f.metadata}
        out = {}
        for f in fields:
            if f.name not in lengths:
                v = plain(getattr(x, f.name))
                out[f.name] = v[: int(getattr(x, f.metadata["length"]))] if "length" in f.metadata else v
        return out
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    if hasattr(x, "shape") and hasattr(x, "dtype"):  # a NumPy or JAX array, or scalar
        return np.asarray(x).tolist()
    return x


def memories(machine, failed_rule: bool = False) -> dict:
    """{memory: {field: value}} of a `VCCState` (one, unbatched) or a `RefMachine`.

    failed_rule: of a failed machine keep only `control.failed` and `control.fail_index`,
    what the two machines agree on after a failure (JAX keeps the state from before the
    failing instruction; the reference may have done part of it)."""
    out = {name: plain(getattr(machine, name)) for name in MEMORIES}
    if failed_rule and out["control"]["failed"]:
        return {"control": {k: out["control"][k] for k in ("failed", "fail_index")}}
    return out


def first_difference(a, b, path: str = "") -> str | None:
    """Where two `memories` views first differ ("attention.attended_list[2]: 3 != 1"), or None."""
    if isinstance(a, dict) and isinstance(b, dict):
        for k in list(a) + [k for k in b if k not in a]:
            if k not in a or k not in b:
                return f"{path}{'.' if path else ''}{k}: only in the {'first' if k in a else 'second'}"
            found = first_difference(a[k], b[k], f"{path}{'.' if path else ''}{k}")
            if found:
                return found
        return None
    if isinstance(a, list) and isinstance(b, list):
        for i, (x, y) in enumerate(zip(a, b)):
            found = first_difference(x, y, f"{path}[{i}]")
            if found:
                return found
        return None if len(a) == len(b) else f"{path}: length {len(a)} != {len(b)}"
    return None if a == b else f"{path}: {a!r} != {b!r}"
