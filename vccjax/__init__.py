"""vccjax: the Visual Cognitive Computer (VCC) emulator in JAX, with a scalar reference.

Quick use::

    from vccjax import parse, random_scene, load_scene, run, run_reference
    program = parse("scene_parse; fixate(left); top_down_attend; fill_color(red)")
"""

from vccjax.concepts import all_concepts, concept_names, reference_program
from vccjax.config import DEFAULT_CONFIG, VCCConfig
from vccjax.emulator import run, run_batch, run_program, run_programs, step, step_batch
from vccjax.errors import DataFileError, ProgramSyntaxError, SceneError, VCCError
from vccjax.generate import random_scene
from vccjax.program import Program, Subroutine, parse
from vccjax.reference import RefMachine, run_reference
from vccjax.scene import Scene, SceneObject, scenes_match
from vccjax.state import SceneConst, VCCState, init_state, load_scene, output_scene

__all__ = [
    "DEFAULT_CONFIG", "DataFileError", "Program", "ProgramSyntaxError", "RefMachine", "Scene",
    "SceneConst", "SceneError", "SceneObject", "Subroutine", "VCCConfig", "VCCError", "VCCState",
    "all_concepts", "concept_names", "init_state", "load_scene", "output_scene", "parse",
    "random_scene", "reference_program", "run", "run_batch", "run_program", "run_programs",
    "run_reference", "scenes_match", "step", "step_batch",
]
