"""vccjax: the Visual Cognitive Computer (VCC) in JAX, with a scalar reference.

The package has four parts (docs/vcc.md is the machine's specification):

- `vccjax.machine`: the VCC itself: instructions, programs, scenes, the JAX machine
  (`state`, `ops`, `step`, `motion`, `match`) and the scalar reference (`reference`).
- `vccjax.world`: where examples come from: the 546 concepts, random scenes and
  programs, example pairs, rival programs, datasets and the shipped data.
- `vccjax.vision`: images: rendering scenes, parsing images back into scenes, and
  measuring that parse.
- `vccjax.views`: looking at runs: traces, the trace viewer, text pictures of scenes.

Quick use::

    from vccjax import parse, random_scene, load_scene, run, run_reference
    program = parse("scene_parse; fixate(left); top_down_attend; fill_color(red)")

Importing `vccjax` is cheap: the names below load their module on first use, so
importing the package starts no JAX backend and loads no OpenCV.
"""

from __future__ import annotations

import importlib

_EXPORTS = {
    "vccjax.machine.config": ("DEFAULT_CONFIG", "VCCConfig"),
    "vccjax.machine.step": ("run", "run_batch", "run_program", "run_programs", "step", "step_batch"),
    "vccjax.errors": ("DataFileError", "ProgramSyntaxError", "SceneError", "VCCError"),
    "vccjax.machine.program": ("Program", "Subroutine", "parse"),
    "vccjax.machine.reference": ("RefMachine", "run_reference"),
    "vccjax.machine.scene": ("Scene", "SceneObject", "scenes_match"),
    "vccjax.machine.state": ("SceneConst", "VCCState", "init_state", "load_scene", "output_scene"),
    "vccjax.world.concepts": ("all_concepts", "concept_names", "reference_program"),
    "vccjax.world.scenes": ("random_scene",),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}

__all__ = sorted(_WHERE)


def __getattr__(name: str):
    """Load a re-exported name's module on first use (PEP 562)."""
    if name not in _WHERE:
        raise AttributeError(f"module 'vccjax' has no attribute {name!r}")
    value = getattr(importlib.import_module(_WHERE[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
