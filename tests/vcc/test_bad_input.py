"""Bad input gets a clear error that names the problem and where it is."""

from __future__ import annotations

import json

import pytest
from tests.helpers import obj, scene

from vccjax.machine.config import VCCConfig
from vccjax.errors import ProgramSyntaxError, SceneError
from vccjax.machine.program import Program, Subroutine, expand, parse
from vccjax.machine.scene import Scene
from vccjax.machine.state import load_scene


@pytest.mark.parametrize(
    "text, words",
    [
        ("", ["empty program"]),
        ("scene_parse; jump", ["instruction 1", "unknown instruction", "jump"]),
        ("scene_parse; fixate", ["instruction 1", "fixate", "one argument"]),
        ("scene_parse; fixate(sideways)", ["instruction 1", "sideways", "left"]),
        ("scene_parse; top_down_attend(red)", ["instruction 1", "takes no argument"]),
        ("scene_parse; set_color_attn(red, blue)", ["instruction 1", "one argument"]),
        ("scene_parse; fill_color()", ["instruction 1", "one argument"]),
        ("scene_parse; fill_color(red", ["instruction 1", "cannot parse"]),
        ("scene_parse; 3d_attend", ["instruction 1", "cannot parse"]),
        ("scene_parse; loop_start; top_down_attend; next_object", ["instruction 1", "without loop_end"]),
        ("scene_parse; top_down_attend; loop_end", ["instruction 2", "without loop_start"]),
        ("scene_parse; loop_start; top_down_attend; loop_start; next_object; loop_end; loop_end",
         ["instruction 3", "nested"]),
        ("scene_parse; loop_start; reset_attn; top_down_attend; next_object; loop_end",
         ["instruction 2", "reset_attn inside a loop"]),
        ("scene_parse; loop_start; top_down_attend; fill_color(red); loop_end",
         ["instruction 4", "lacks next_object"]),
        # a program file: the line too, counted with comments and blank lines
        ("scene_parse\n# recolour it\n\ntop_down_attend\nfill_color(purple)\n",
         ["instruction 2 (line 5)", "purple"]),
        ("scene_parse\nfoo(\n", ["instruction 1 (line 2)", "cannot parse"]),
        ("scene_parse; top_down_attend\nloop_end", ["instruction 2 (line 2)", "without loop_start"]),
    ],
)
def test_malformed_program_text(text, words):
    with pytest.raises(ProgramSyntaxError) as e:
        parse(text)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_a_byte_order_mark_is_not_part_of_the_first_instruction():
    assert parse("\ufeffscene_parse; top_down_attend") == parse("scene_parse; top_down_attend")


def test_long_loop_body_is_refused_when_a_limit_is_given():
    body = "; ".join(["fill_color(red)"] * 30)
    with pytest.raises(ProgramSyntaxError, match="exceeds body_max=24"):
        parse(f"scene_parse; loop_start; top_down_attend; {body}; next_object; loop_end", body_max=24)


def test_text_round_trip_and_comments():
    text = "scene_parse; set_shape_attn(star); loop_start; top_down_attend; fill_color(blue); next_object; loop_end"
    p = parse(text)
    assert p.text() == text
    assert parse("# a comment\n" + p.text(sep="\n")) == p
    assert Program.from_steps(p.steps()) == p


def test_typed_program_refuses_out_of_domain_indices():
    with pytest.raises(ProgramSyntaxError, match="unknown op index 99"):
        Program((0, 99), (0, 0))
    with pytest.raises(ProgramSyntaxError, match="argument index 7 out of domain"):
        Program((0, 5), (0, 7))  # set_shape_attn has 5 shapes
    with pytest.raises(ProgramSyntaxError, match="ops and args differ"):
        Program((0,), ())
    with pytest.raises(ProgramSyntaxError, match=r"\[name, arg\]"):
        Program.from_steps([["scene_parse"]])


def test_subroutines_expand_with_their_atoms_arguments():
    lib = {
        "pick": Subroutine("pick", ("top_down_attend", "move_hand_to_attended_object", "grab_object")),
        "paint": Subroutine("paint", ("set_color_attn", "pick", "fill_color")),
    }
    p = parse("scene_parse; paint(red, blue); release_object", lib)
    assert p.text() == ("scene_parse; set_color_attn(red); top_down_attend; move_hand_to_attended_object; "
                        "grab_object; fill_color(blue); release_object")
    with pytest.raises(ProgramSyntaxError, match="subroutine paint takes 2 argument"):
        parse("scene_parse; paint(red)", lib)
    with pytest.raises(ProgramSyntaxError, match="unknown instruction or subroutine 'dance'"):
        expand([("dance", [])], lib)
    cyclic = {"a": Subroutine("a", ("b",)), "b": Subroutine("b", ("a",))}
    with pytest.raises(ProgramSyntaxError, match="nests more than 32 deep"):
        expand([("a", [])], cyclic)


def test_overlapping_objects():
    with pytest.raises(SceneError, match=r"objects 0 .*and 1 .*overlap"):
        scene(obj("square", "red", 0.5, 0.5), obj("circle", "blue", 0.55, 0.5)).validate()


@pytest.mark.parametrize("x, y", [(0.02, 0.5), (0.5, 0.97), (1.2, 0.5), (-0.1, 0.2)])
def test_out_of_bounds_objects(x, y):
    with pytest.raises(SceneError, match="object 0 .* lies outside the workspace"):
        load_scene(scene(obj("square", "red", x, y)))


def test_too_many_objects():
    objs = [obj("circle", "red", 0.1 + 0.08 * i, 0.5, 0.05) for i in range(11)]
    with pytest.raises(SceneError, match="11 objects; at most 10"):
        load_scene(Scene(tuple(objs)))
    assert load_scene(Scene(tuple(objs)), VCCConfig(n_max=12)).n == 11


def test_bad_object_fields():
    with pytest.raises(SceneError, match="unknown shape 'hexagon'"):
        obj("hexagon", "red", 0.5, 0.5)
    with pytest.raises(SceneError, match="unknown color 'purple'"):
        obj("square", "purple", 0.5, 0.5)
    with pytest.raises(SceneError, match="finite number"):
        obj("square", "red", float("nan"), 0.5)
    with pytest.raises(SceneError, match="width must be in"):
        scene(obj("square", "red", 0.5, 0.5, 0.4)).validate()
    with pytest.raises(SceneError, match="pointer"):
        scene(obj("square", "red", 0.5, 0.5), pointer=(1.5, 0.5)).validate()


def test_scene_files(tmp_path):
    good = scene(obj("star", "yellow", 0.3, 0.3), pointer=(0.6, 0.6))
    good.save(tmp_path / "s.json")
    assert Scene.load(tmp_path / "s.json") == good
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(SceneError, match="bad.json: not a JSON scene file"):
        Scene.load(tmp_path / "bad.json")
    with pytest.raises(SceneError, match="no such scene file"):
        Scene.load(tmp_path / "missing.json")
    (tmp_path / "foreign.json").write_text(json.dumps({"objects": [{"shape": "square"}]}))
    with pytest.raises(SceneError, match=r"object 0 lacks \['color', 'width', 'x', 'y'\]"):
        Scene.load(tmp_path / "foreign.json")
    (tmp_path / "list.json").write_text("[1, 2]")
    with pytest.raises(SceneError, match="'objects' list"):
        Scene.load(tmp_path / "list.json")


def test_config_limits():
    with pytest.raises(ValueError, match="n_max must be at least 10"):
        VCCConfig(n_max=5)
    with pytest.raises(ValueError, match="raster must be in"):
        VCCConfig(raster=2048)
