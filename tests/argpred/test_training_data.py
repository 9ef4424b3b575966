"""Argument prediction's training data: the features of a pair, and the programs drawn,
labelled, built into seeded shards and loaded (drawn, loop and carry kinds)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from argpred import data as argdata
from argpred.features import CHANNEL_NAMES, CHANNELS, GRID, pair_features
from vccjax.errors import DataFileError
from vccjax.machine.program import check_loop_syntax, parse
from vccjax.machine.scene import Scene, SceneObject


def test_features_of_a_hand_built_pair_mean_what_the_channels_say():
    # a red square at the centre turns blue; a green circle at the top left stays
    before = Scene((SceneObject("square", "red", 0.5, 0.5, 0.1), SceneObject("circle", "green", 0.1, 0.1, 0.1)),
                   pointer=(0.9, 0.2))
    after = Scene((SceneObject("square", "blue", 0.5, 0.5, 0.1), SceneObject("circle", "green", 0.1, 0.1, 0.1)),
                  pointer=(0.9, 0.2))
    f = pair_features([(before, after)])
    assert f.shape == (1, CHANNELS, GRID, GRID) and len(CHANNEL_NAMES) == CHANNELS
    ch = {name: f[0, k] for k, name in enumerate(CHANNEL_NAMES)}
    assert ch["in:square"][7, 7] == 1 and ch["in:red"][7, 7] == 1  # floor(0.5 * 14) = 7 (row, column)
    assert ch["in:circle"][1, 1] == 1 and ch["in:green"][1, 1] == 1
    assert ch["in:pointer"][2, 12] == 1 and ch["in:pointer"].sum() == 1  # row from y = 0.2, column from x = 0.9
    assert ch["diff:red"][7, 7] == -1 and ch["diff:blue"][7, 7] == 1
    assert ch["diff:square"].sum() == 0 and ch["diff:green"].sum() == 0 and ch["diff:pointer"].sum() == 0
    assert ch["changed"][7, 7] == 1 and ch["changed"].sum() == 1
    # a move: gone from one cell, present in another
    moved = Scene((SceneObject("square", "red", 0.9, 0.5, 0.1), before.objects[1]), pointer=(0.9, 0.2))
    g = dict(zip(CHANNEL_NAMES, pair_features([(before, moved)])[0]))
    assert g["diff:square"][7, 7] == -1 and g["diff:square"][7, 12] == 1 and g["changed"].sum() == 2


def test_drawn_programs_pass_the_filters_and_are_labelled():
    rng = np.random.default_rng(3)
    pool = argdata.scene_pool(rng, 40)
    for _ in range(5):
        program, pairs = argdata.kept_program(rng, pool)
        assert len(pairs) == 10 and argdata.LENGTHS[0] <= len(program) <= argdata.LENGTHS[1]
        assert argdata.indispensable(program, pairs)
        assert all(a != b for a, b in pairs)  # every example changes
    labels = argdata.labels_of(parse("scene_parse; set_color_attn(red); top_down_attend; fill_color(blue)"))
    on = {argdata.LABELS[k] for k in np.nonzero(labels)[0]}
    assert on == {("set_color_attn", "red"), ("fill_color", "blue")}
    # a filter that changes nothing is dispensable: both squares would turn blue anyway
    both = Scene((SceneObject("square", "red", 0.3, 0.3, 0.1), SceneObject("square", "red", 0.7, 0.7, 0.1)))
    loop = parse("scene_parse; set_shape_attn(square); loop_start; top_down_attend; fill_color(blue); "
                 "next_object; loop_end")
    from vccjax.machine.reference import RefMachine

    out = RefMachine(both).run(loop).output_scene()
    assert not argdata.indispensable(loop, [(both, out)])


def test_shards_are_seeded_and_data_loads_verified(tiny):
    again = argdata.build_shard(seed=5, shard=0, size=24)
    with np.load(tiny / "shard0000.npz") as z:
        assert all(np.array_equal(z[k], again[k]) for k in again)
    d = argdata.load(tiny)
    assert d["inputs"].shape == (24, 10, 9, 4) and d["labels"].shape == (24, len(argdata.LABELS))
    assert len(d["programs"]) == 24
    # `train --data` keeps them all
    assert argdata.built(tiny) == {"programs": 24, "seed": 5, "joined": 0.0, "kind": "drawn"}
    assert argdata.built(tiny / "none") is None
    with pytest.raises(DataFileError, match="built with seed 5, joined 0.0, kind drawn"):
        argdata.build(tiny, 24, seed=6)  # refused, not rebuilt: nothing drawn is lost
    (tiny / "extra").mkdir(exist_ok=True)
    bad = tiny / "extra"
    (bad / "manifest.json").write_text(json.dumps({"format": "something else"}))
    with pytest.raises(DataFileError, match="not a vccjax-argpred-data"):
        argdata.load(bad)


def test_loop_programs_do_one_change_to_every_attended_object(tmp_path):
    folder = tmp_path / "loop"
    argdata.build(folder, 6, seed=3, progress=False, kind="loop")
    assert argdata.built(folder) == {"programs": 6, "seed": 3, "joined": 0.0, "kind": "loop"}
    d = argdata.load(folder)
    assert d["inputs"].shape == (6, 10, 9, 4)
    for text, labels in zip(d["programs"], d["labels"]):
        program = parse(text)
        check_loop_syntax(program)  # a whole loop: loop_start; top_down_attend; ...; next_object; loop_end
        steps = text.split("; ")
        assert steps[-1] == "loop_end" and steps[-2] == "next_object" and steps.count("loop_start") == 1
        before = steps[: steps.index("loop_start")]  # only a selection before the loop
        assert all(s.split("(")[0] in ("scene_parse", "set_shape_attn", "set_color_attn", "fixate") for s in before)
        assert np.array_equal(labels, argdata.labels_of(program))
    again = argdata.build_shard(3, 0, size=6, kind="loop")
    with np.load(folder / "shard0000.npz") as z:
        assert all(np.array_equal(z[k], again[k]) for k in again)
    with pytest.raises(DataFileError, match="kind loop"):
        argdata.build(folder, 6, seed=3, progress=False, kind="carry")  # another kind into a loop folder: refused


def test_carry_programs_are_seeded_two_attend_procedures_in_their_own_folder(tmp_path):
    folder = tmp_path / "carry"
    argdata.build(folder, 5, seed=2, progress=False, kind="carry")
    assert argdata.built(folder) == {"programs": 5, "seed": 2, "joined": 0.0, "kind": "carry"}
    d = argdata.load(folder)
    assert d["inputs"].shape == (5, 10, 9, 4) and len(d["programs"]) == 5
    for text in d["programs"]:  # pick, grab, then attend a second object and carry the first onto it
        steps = text.split("; ")
        assert steps.count("top_down_attend") == 2 and steps.count("grab_object") == 1
        assert steps.index("grab_object") < len(steps) - 1 - steps[::-1].index("top_down_attend")
    again = argdata.build_shard(2, 0, size=5, kind="carry")
    with np.load(folder / "shard0000.npz") as z:
        assert all(np.array_equal(z[k], again[k]) for k in again)
    with pytest.raises(DataFileError, match="kind carry"):
        argdata.build(folder, 5, seed=2, progress=False)  # a drawn build into a carry folder: refused
    with pytest.raises(ValueError, match="not joined"):
        argdata.build(tmp_path / "other", 5, seed=2, progress=False, kind="carry", joined=0.3)
    with pytest.raises(ValueError, match="unknown kind"):
        argdata.build(tmp_path / "other", 5, kind="enumerated")
