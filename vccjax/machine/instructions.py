"""The instruction set: names, reference ids, compact op indices and argument domains."""

from __future__ import annotations

SHAPES: tuple[str, ...] = ("square", "circle", "diamond", "triangle", "star")
COLORS: tuple[str, ...] = ("red", "green", "blue", "yellow")
FIXATE_TARGETS: tuple[str, ...] = ("left", "right", "top", "bottom", "center")
IMAGINE_KINDS: tuple[str, ...] = ("circle", "hline")

# Reference instruction ids of the paper's code (docs/vcc.md section 3); 15 and 24 are unused.
REFERENCE_IDS: dict[str, int] = {
    "scene_parse": 0,
    "top_down_attend": 1,
    "move_hand_to_attended_object": 2,
    "grab_object": 3,
    "move_hand_to_pointer": 4,
    "set_shape_attn": 5,
    "set_color_attn": 6,
    "move_hand_left": 7,
    "move_hand_right": 8,
    "move_hand_up": 9,
    "move_hand_down": 10,
    "fixate": 11,
    "release_object": 12,
    "fill_color": 13,
    "next_object": 14,
    "reset_attn": 16,
    "fixate_attended_object": 17,
    "fixate_previous": 18,
    "move_hand_to_fixate_collision": 19,
    "fixate_next": 20,
    "fixate_pointer": 21,
    "remove_from_imagine_buffer": 22,
    "attend_pointer": 23,
    "loop_start": 25,
    "loop_end": 26,
    "reset_imagination": 27,
    "imagine_object": 28,
}

# Compact op index (0..26), ordered by reference id: what `lax.switch` and the search index.
NAMES: tuple[str, ...] = tuple(sorted(REFERENCE_IDS, key=REFERENCE_IDS.__getitem__))
OP: dict[str, int] = {name: i for i, name in enumerate(NAMES)}
N_OPS: int = len(NAMES)

ARG_DOMAINS: dict[str, tuple[str, ...]] = {
    "set_shape_attn": SHAPES,
    "set_color_attn": COLORS,
    "fill_color": COLORS,
    "fixate": FIXATE_TARGETS,
    "imagine_object": IMAGINE_KINDS,
}


def arg_domain(name: str) -> tuple[str, ...]:
    """Argument values an instruction takes; empty for instructions without one."""
    return ARG_DOMAINS.get(name, ())


# Instructions that may not appear inside a loop body (docs/vcc.md section 5).
FORBIDDEN_IN_LOOP: frozenset[str] = frozenset(
    {"set_shape_attn", "set_color_attn", "reset_attn", "loop_start"}
)
REQUIRED_IN_LOOP: frozenset[str] = frozenset({"top_down_attend", "next_object"})

assert N_OPS == 27
