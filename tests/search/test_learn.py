"""`vcc learn`: a concept from a folder of the user's pairs (scenes or pictures), a
question back when two pairs leave it ambiguous, the answer settling it, a learned
concept saved and run by name, and every kind of bad input refused with one line and
nothing written."""

from __future__ import annotations

import json
import os

import cv2
import numpy as np
import pytest

from argpred.features import MAX_OBJECTS
from search.learn import LearnSettings, learn
from search.library import shipped_library
from search.scalar import ScalarExplorer
from vcc.cli import main
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.program import parse
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, SceneObject, scenes_match
from vccjax.vision.examples_folder import read_pairs
from vccjax.vision.render import render
from vccjax.world.concepts import reference_program
from vccjax.world.dataset import dataset_for

CONCEPT = "remove_bottom_obj"  # its first two training pairs: the bottom object is also the right-most
TAU = DEFAULT_CONFIG.tau
QUICK = ["--engine", "reference", "--budget", "20000", "--quiet"]


@pytest.fixture(scope="module")
def data():
    return dataset_for([CONCEPT], 0, None, progress=False)


def _png(path, scene: Scene) -> None:
    cv2.imwrite(str(path), cv2.cvtColor(render(scene, 384), cv2.COLOR_RGB2BGR))


def _folder(path, pairs, keys=None, png=()):
    path.mkdir(parents=True, exist_ok=True)
    for k, (a, b) in zip(keys or range(len(pairs)), pairs, strict=True):
        for side, s in (("in", a), ("out", b)):
            if k in png:
                _png(path / f"{k}_{side}.png", s)
            else:
                s.save(path / f"{k}_{side}.json")
    return path


def same_output(m, answer) -> bool:
    return not m.failed and scenes_match(m.output_scene(), answer.output_scene(), TAU)


def _explains(program, pairs) -> bool:
    for a, b in pairs:
        m = RefMachine(a).run(program)
        if m.failed or not scenes_match(m.output_scene(), b, TAU):
            return False
    return True


def test_pairs_are_read_from_scenes_pictures_or_both_in_natural_order(data, tmp_path):
    pairs = data.pairs(CONCEPT, "train")[:3]
    for png in ((), (2, 10, 1), (10,)):
        folder = _folder(tmp_path / f"f{len(png)}", pairs, keys=[2, 10, 1], png=png)
        got = read_pairs(folder)
        assert [k for k, _, _ in got] == ["1", "2", "10"]  # 2 before 10
        for (_, a, b), (x, y) in zip(got, [pairs[2], pairs[0], pairs[1]], strict=True):
            assert scenes_match(a, x, TAU) and scenes_match(b, y, TAU)


def test_two_ambiguous_pairs_get_a_question_and_the_answer_settles_it(data):
    truth = reference_program(CONCEPT)
    two = data.pairs(CONCEPT, "train")[:2]
    settings = LearnSettings(budget=20_000)
    first = learn(two, settings, ScalarExplorer(width=1))
    assert first.found and _explains(first.program, two) and first.ambiguous
    rivals = first.rivals()
    assert rivals and all(_explains(p, two) for p, *_ in rivals)
    # the query: an input on which the rivals' outputs differ (checked on the reference)
    q = first.query_scene
    outs = [RefMachine(q).run(first.candidates()[i][0]) for i in first.verdict.programs]
    done = [m.output_scene() for m in outs if not m.failed]
    assert len(done) >= 2 and any(not scenes_match(done[0], o, TAU) for o in done[1:])
    # answered with what the concept does there, the three pairs settle it
    answer = RefMachine(q).run(truth)
    assert not answer.failed
    settled = learn([*two, (q, answer.output_scene())], settings, ScalarExplorer(width=1))
    assert settled.found and _explains(settled.program, data.pairs(CONCEPT, "test"))
    assert not _explains(first.program, data.pairs(CONCEPT, "test"))  # the first guess was wrong
    # every candidate the answer ruled out is gone: none gives the query's other outputs
    wrong = [first.candidates()[first.verdict.programs[k]][0] for g in first.verdict.answers for k in g
             if not same_output(RefMachine(q).run(first.candidates()[first.verdict.programs[k]][0]), answer)]
    assert wrong and not {p.text() for p in wrong} & {p.text() for p, _, _ in settled.candidates()}


def test_learn_writes_the_concept_saves_it_and_runs_it_by_name(data, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("VCC_LIBRARY", str(tmp_path / "lib"))
    pairs = data.pairs(CONCEPT, "train")[:3]
    folder = _folder(tmp_path / "ex", pairs, png=(2,))  # two scene files, one pair of pictures
    out = tmp_path / "out"
    assert main(["learn", str(folder), "--out", str(out), "--name", "drop_lowest", "--save", "--budget", "20000",
                 "--quiet"]) == 0  # the JAX engine, as users run it
    c = json.loads((out / "concept.json").read_text())
    program = parse(c["program"])
    assert _explains(program, pairs) and c["pairs_right"] == c["pairs"] == 3
    assert c["ambiguous"] is False and (out / "trace.png").stat().st_size > 0
    assert not (out / "query.json").exists()
    assert c["library"] == json.loads(shipped_library().read_text())["content_sha256"]
    capsys.readouterr()
    assert main(["run", "--concept", "drop_lowest", "--scene", str(folder / "0_in.json")]) == 0
    assert "changed" in capsys.readouterr().out
    assert main(["trace", "--concept", "drop_lowest", "--scene", str(folder / "1_in.json"),
                 "--out", str(tmp_path / "t.png")]) == 0
    saved = tmp_path / "lib" / "drop_lowest.json"
    saved.write_text(saved.read_text().replace("remove_from_imagine_buffer", "fill_color(red)"))
    assert main(["run", "--concept", "drop_lowest", "--scene", str(folder / "0_in.json")]) == 2
    assert "content sha256 mismatch" in capsys.readouterr().err


def test_a_rerun_with_the_answer_replaces_the_question(data, tmp_path):
    two = data.pairs(CONCEPT, "train")[:2]
    folder, out = _folder(tmp_path / "ex", two), tmp_path / "out"
    assert main(["learn", str(folder), "--out", str(out), *QUICK]) == 0
    q = json.loads((out / "query.json").read_text())
    assert len(q["answers"]) >= 2 and (out / "query.png").exists() and (out / "query_in.json").exists()
    scene = Scene.load(out / "query_in.json")
    (folder / "q_in.json").write_text((out / "query_in.json").read_text())
    RefMachine(scene).run(reference_program(CONCEPT)).output_scene().save(folder / "q_out.json")
    assert main(["learn", str(folder), "--out", str(out), *QUICK]) == 0
    learned = json.loads((out / "concept.json").read_text())
    assert _explains(parse(learned["program"]), data.pairs(CONCEPT, "test"))
    if learned["ambiguous"]:  # a new question, and nothing left of the old one
        again = json.loads((out / "query.json").read_text())
        assert again["input"] != q["input"]
        assert sorted(p.name for p in out.glob("query_out_*.json")) == sorted(
            f"query_out_{a['answer']}.json" for a in again["answers"] if a["output"] is not None)
    else:
        assert not [p.name for p in out.glob("query*")]


def _blank(path, color=None) -> None:
    img = np.full((256, 256, 3), 255, np.uint8)
    if color is not None:
        cv2.rectangle(img, (100, 100), (140, 140), color, -1)
    cv2.imwrite(str(path), img)


def _bad_cases(tmp_path, pairs):
    a, b = pairs[0]
    extra = Scene(a.objects + (SceneObject("star", "red", 0.9, 0.1, 0.08),), a.pointer)  # one more than the input
    crowded = Scene(tuple(SceneObject("circle", "red", 0.15 + 0.23 * (k % 4), 0.2 + 0.3 * (k // 4), 0.08)
                          for k in range(MAX_OBJECTS + 1)), None)
    reshaped = Scene(tuple(SceneObject("circle" if o.shape != "circle" else "square", o.color, o.x, o.y, o.width)
                           for o in a.objects[:1]), None)
    return {
        "empty": (lambda d: d.mkdir(), "holds no example pairs"),
        "no such folder": (lambda d: None, "no such examples folder"),
        "half a pair": (lambda d: (_folder(d, [pairs[0]]), os.remove(d / "0_out.json")), "has no out file"),
        "two inputs": (lambda d: (_folder(d, [pairs[0]]), _png(d / "0_in.png", a)), "already has an in file"),
        "stray file": (lambda d: (_folder(d, [pairs[0]]), (d / "notes.txt").write_text("x")), "not half of a pair"),
        "bad json": (lambda d: (_folder(d, [pairs[0]]), (d / "0_in.json").write_text("{")), "0_in.json: not"),
        "bad png": (lambda d: (_folder(d, [pairs[0]]), os.remove(d / "0_in.json"),
                               (d / "0_in.png").write_bytes(b"not a png")), "not an image OpenCV can read"),
        "no objects": (lambda d: (_folder(d, [pairs[0]]), os.remove(d / "0_in.json"), _blank(d / "0_in.png")),
                       "no objects found"),
        "unknown colour": (lambda d: (_folder(d, [pairs[0]]), os.remove(d / "0_in.json"),
                                      _blank(d / "0_in.png", (200, 0, 200))), "unknown color"),
        "object from nowhere": (lambda d: _folder(d, [(a, extra)]), "never makes one"),
        "shape changed": (lambda d: _folder(d, [(a, reshaped)]), "has no"),
        "a file": (lambda d: d.write_text("x"), "not a folder of example pairs"),
        "empty table": (lambda d: _folder(d, [(Scene((), None), Scene((), None))]), "0_in.json: no objects"),
        "one input, two outputs": (lambda d: _folder(d, [(a, b), (a, a)]), "1_out.json: its input is 0_in.json's"),
        "more than the predictor reads": (lambda d: _folder(d, [(crowded, crowded)]),
                                          f"0_in.json: {len(crowded.objects)} objects; the argument predictor"),
    }


@pytest.mark.parametrize("case", ["empty", "no such folder", "half a pair", "two inputs", "stray file", "bad json",
                                  "bad png", "no objects", "unknown colour", "object from nowhere", "shape changed",
                                  "a file", "empty table", "one input, two outputs", "more than the predictor reads"])
def test_bad_examples_are_refused_in_one_line_and_nothing_is_written(data, tmp_path, capsys, case):
    make, message = _bad_cases(tmp_path, data.pairs(CONCEPT, "train"))[case]
    folder, out = tmp_path / "ex", tmp_path / "out"
    make(folder)
    assert main(["learn", str(folder), "--out", str(out), *QUICK]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err
    assert not out.exists()


def test_an_out_folder_inside_the_examples_is_refused(data, tmp_path, capsys):
    """Its files would be read as pairs on the next run."""
    folder = _folder(tmp_path / "ex", data.pairs(CONCEPT, "train")[:2])
    for out in (folder, folder / "out"):
        assert main(["learn", str(folder), "--out", str(out), *QUICK]) == 2
        err = capsys.readouterr().err.strip()
        assert "inside the examples folder" in err and len(err.splitlines()) == 1, err
    assert sorted(p.name for p in folder.iterdir()) == ["0_in.json", "0_out.json", "1_in.json", "1_out.json"]


@pytest.mark.parametrize("flags, message", [
    (["--fixate", "up"], "--fixate up"),
    (["--save"], "--save needs --name"),
    (["--name", "Bad Name", "--save"], "--name 'Bad Name'"),
    (["--name", CONCEPT, "--save"], "a shipped concept has this name"),
    (["--budget", "0"], "argument --budget: 0 is out of range"),
    (["--library", "no/such/library.json"], "no/such/library.json: missing"),
    (["--budget", "3"], "no program under the budget"),
])
def test_bad_options_and_nothing_found_exit_non_zero(data, tmp_path, capsys, flags, message):
    folder, out = _folder(tmp_path / "ex", data.pairs(CONCEPT, "train")[:2]), tmp_path / "out"
    assert main(["learn", str(folder), "--out", str(out), "--engine", "reference", "--quiet", *flags]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err
    assert not out.exists()


def test_an_answered_question_keeps_a_rival_the_budget_alone_would_not_reach(data):
    """`settle`: the programs a question was about are weighed with the search's; one that
    explains every pair is kept even when the budget's cutoff lies below it, and one that
    does not explain them is never taken."""
    truth = reference_program(CONCEPT)
    pairs = data.pairs(CONCEPT, "train")[:3]
    tiny = LearnSettings(budget=1, rival_budget=0)
    assert not learn(pairs, tiny, ScalarExplorer(width=1)).found
    wrong = parse("scene_parse; fixate(right); top_down_attend; remove_from_imagine_buffer")
    assert not _explains(wrong, pairs)
    got = learn(pairs, tiny, ScalarExplorer(width=1), asked=[wrong, truth])
    assert got.found and got.program == truth and got.result.rank > 1
    assert not learn(pairs, tiny, ScalarExplorer(width=1), asked=[wrong]).found


def test_a_programs_cheapest_spelling_is_what_the_search_paid_or_less(data):
    from search.learn import chain_for

    pairs = data.pairs(CONCEPT, "train")[:3]
    settings = LearnSettings(budget=20_000, rival_budget=0)
    found = learn(pairs, settings, ScalarExplorer(width=1)).result
    chain, _ = chain_for(pairs, settings)
    nats, portions = chain.cheapest(found.program.ops, found.program.args)
    assert nats <= found.dl_nats + 1e-9 and abs(chain.program_nats(portions) - nats) < 1e-9
    assert chain.cheapest(found.program.ops[1:], found.program.args[1:]) is None  # no scene_parse first


def test_a_rerun_with_the_answer_weighs_the_programs_asked_about(data, tmp_path, capsys):
    """The user answers the question and reruns in the same folder with a budget too small
    to find anything: the answer still settles it among the programs asked about."""
    two = data.pairs(CONCEPT, "train")[:2]
    folder, out = _folder(tmp_path / "ex", two), tmp_path / "out"
    assert main(["learn", str(folder), "--out", str(out), *QUICK]) == 0
    (folder / "q_in.json").write_text((out / "query_in.json").read_text())
    scene = Scene.load(out / "query_in.json")
    RefMachine(scene).run(reference_program(CONCEPT)).output_scene().save(folder / "q_out.json")
    capsys.readouterr()
    assert main(["learn", str(folder), "--out", str(out), "--engine", "reference", "--budget", "1", "--quiet"]) == 0
    assert "the pairs answer the question" in capsys.readouterr().out
    learned = json.loads((out / "concept.json").read_text())
    assert _explains(parse(learned["program"]), data.pairs(CONCEPT, "test"))
    # a concept.json that is not one of vcc learn's is refused, naming it
    (out / "concept.json").write_text(json.dumps({"program": "no_such_op", "rivals": [], "examples": [],
                                                  "ambiguous": True}))
    assert main(["learn", str(folder), "--out", str(out), *QUICK]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "concept.json" in err[0]


def test_what_the_library_misses_is_tried_from_a_uniform_start_over_a_tenth_of_the_budget():
    """A start that all but rules out `set_shape_attn` finds nothing for a concept that
    picks its object by shape; the uniform start's first tenth of the budget finds a
    program that fits every pair, the judged programs add up, and a start that was
    uniform already is not searched again."""
    from search.chain import Chain
    from search.learn import chain_for, from_uniform, model_for
    from search.model import MarkovModel, Vocabulary
    from search.task import Task
    from vccjax.machine.instructions import OP

    concept = "change_target_obj_to_given_color"
    pairs = dataset_for([concept], 0, None, progress=False).pairs(concept, "train")[:4]
    size = Vocabulary().size
    logp = np.full((size + 1, size + 1), -np.log(size + 1))
    logp[:, OP["set_shape_attn"]] = -60.0  # `set_shape_attn` past any budget here
    skewed = (Vocabulary(), MarkovModel(logp, 1, 0.0), "skewed")
    settings = LearnSettings(budget=200_000, rival_budget=0, parts=1)
    chain: Chain = chain_for(pairs, settings, skewed)[0]
    searcher = ScalarExplorer(width=1)
    missed = searcher.search(chain, Task.from_pairs(pairs), settings.budget)
    assert not missed.found
    got, uniform = from_uniform(missed, pairs, settings, searcher, skewed)
    assert got.found and uniform is not None and got.programs > missed.programs
    assert got.rank <= settings.budget // 10
    for a, b in pairs:
        m = RefMachine(a).run(got.program)
        assert not m.failed and scenes_match(m.output_scene(), b, DEFAULT_CONFIG.tau)
    again, none = from_uniform(missed, pairs, settings, searcher, model_for("uniform"))
    assert again is missed and none is None
