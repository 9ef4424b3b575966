"""Learning in parts (`search.parts`): the scene distance it climbs, what counts as
progress, and a two-part concept past the budget learned from its parts."""

from __future__ import annotations

import itertools
import random

import pytest

from search.learn import LearnSettings, chain_for, learn
from search.parts import fits, gains, join_nats, joins
from search.scalar import ScalarExplorer
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.program import parse
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, SceneObject, matching_size, scene_distance, scenes_match
from vccjax.world.dataset import dataset_for

TAU = DEFAULT_CONFIG.tau
TWO_PARTS = ("scene_parse; fixate(top); top_down_attend; fill_color(red); reset_attn; "
             "fixate(bottom); top_down_attend; fill_color(blue)")
REMOVE_THEN_RECOLOR = ("scene_parse; fixate(left); top_down_attend; remove_from_imagine_buffer; "
                       "fixate(right); top_down_attend; fill_color(yellow)")
RECOLOR_THEN_REMOVE = ("scene_parse; fixate(right); top_down_attend; fill_color(yellow); reset_attn; "
                       "fixate(left); top_down_attend; remove_from_imagine_buffer")


def _obj(shape, color, x, y):
    return SceneObject(shape, color, x, y, 0.1)


def _brute_matching(a: Scene, b: Scene) -> int:
    """The most pairs over every way to pair objects of `a` with distinct objects of `b`."""
    def ok(p, q):
        return p.shape == q.shape and p.color == q.color and (p.x - q.x) ** 2 + (p.y - q.y) ** 2 <= TAU * TAU

    best = 0
    small, large = (a.objects, b.objects) if len(a.objects) <= len(b.objects) else (b.objects, a.objects)
    for chosen in itertools.permutations(range(len(large)), len(small)):
        best = max(best, sum(ok(small[i], large[j]) for i, j in enumerate(chosen)))
    return best


def test_scene_distance_counts_the_objects_a_best_pairing_leaves_over():
    """Against brute force over every pairing, on scenes crowded with look-alikes (same
    shape and colour within tau of several others), where a greedy pairing would err."""
    rng = random.Random(0)
    pool = [("square", "red"), ("circle", "red"), ("square", "blue")]
    for _ in range(300):
        def scene(n):
            return Scene(tuple(_obj(*rng.choice(pool), rng.choice([0.3, 0.3 + TAU * 0.8, 0.3 + TAU * 1.6]), 0.5)
                               for _ in range(n)))

        a, b = scene(rng.randint(0, 4)), scene(rng.randint(0, 4))
        m = _brute_matching(a, b)
        assert matching_size(a, b, TAU) == m
        assert scene_distance(a, b, TAU) == len(a.objects) + len(b.objects) - 2 * m
        assert (scene_distance(a, b, TAU) == 0) == scenes_match(a, b, TAU)


def test_progress_is_closer_on_some_pair_farther_on_none_and_no_object_lost_for_good():
    top, bottom = _obj("square", "green", 0.5, 0.2), _obj("circle", "green", 0.5, 0.8)
    given = Scene((top, bottom))
    want = Scene((_obj("square", "red", 0.5, 0.2), _obj("circle", "blue", 0.5, 0.8)))
    half = Scene((_obj("square", "red", 0.5, 0.2), bottom))
    pair = (given, want)
    assert gains([half], [pair], TAU) == [2]  # one object right: itself and its output counterpart paired
    assert gains([given], [pair], TAU) is None  # nothing changed
    assert gains([None], [pair], TAU) is None  # the program failed
    assert gains([half, given], [pair, pair], TAU) == [2, 0]  # a pair already done may stay as it was
    wrong = Scene((_obj("square", "yellow", 0.5, 0.2), bottom))
    assert gains([wrong], [pair], TAU) is None  # a change that is not the output's is no progress
    done = (Scene((top, want.objects[1])), want)  # the bottom object already right
    broken = Scene((top, _obj("circle", "yellow", 0.5, 0.8)))
    assert gains([half, broken], [pair, done], TAU) is None  # ... and no pair may get farther
    # removing a misplaced object shortens the distance by one, yet nothing can put it back
    moved = (given, Scene((top, _obj("circle", "green", 0.2, 0.8))))
    assert scene_distance(Scene((top,)), moved[1], TAU) < scene_distance(given, moved[1], TAU)
    assert gains([Scene((top,))], [moved], TAU) is None
    removal = (given, Scene((top,)))  # ... while removing what the output lacks is progress
    assert gains([Scene((top,))], [removal], TAU) == [1]


def test_joins_drop_the_rests_scene_parse_with_and_without_a_reset():
    first, rest = parse("scene_parse; fixate(top)"), parse("scene_parse; top_down_attend")
    assert [j.text() for j in joins(first, rest)] == [
        "scene_parse; fixate(top); top_down_attend", "scene_parse; fixate(top); reset_attn; top_down_attend"]


@pytest.fixture(scope="module")
def two_part_pairs():
    """Scenes of two objects or more, each made into a pair by TWO_PARTS (recolor the top
    object red, then the bottom one blue): a program whose join the library rarely saw."""
    data = dataset_for(["remove_bottom_obj"], 0, None, progress=False)
    truth = parse(TWO_PARTS)
    pairs = []
    for split in ("train", "test"):
        for a, _ in data.pairs("remove_bottom_obj", split):
            m = RefMachine(a).run(truth)
            if not m.failed and scene_distance(a, m.output_scene(), TAU) == 4:  # both objects change
                pairs.append((a, m.output_scene()))
    return pairs


def test_a_two_part_concept_past_the_budget_is_learned_in_parts(two_part_pairs):
    train, held_out = two_part_pairs[:6], two_part_pairs[6:]
    assert len(held_out) >= 10
    whole = LearnSettings(budget=20_000, rival_budget=0, parts=1)
    assert not learn(train, whole, ScalarExplorer(width=1)).found  # the whole program ranks past the budget
    got = learn(train, LearnSettings(budget=20_000, rival_budget=0), ScalarExplorer(width=1))
    assert got.found and len(got.parts) == 2
    for a, b in train + held_out:  # right on the pairs and on others like them
        m = RefMachine(a).run(got.program)
        assert not m.failed and scenes_match(m.output_scene(), b, TAU)
    assert got.result.rank > 20_000  # its rank under the model lies past the budget


def test_vcc_learn_reports_the_parts_and_writes_them(two_part_pairs, tmp_path, capsys):
    import json

    from tests.search.test_learn import _folder
    from vcc.cli import main

    folder, out = _folder(tmp_path / "ex", two_part_pairs[:6]), tmp_path / "out"
    assert main(["learn", str(folder), "--out", str(out), "--engine", "reference", "--budget", "20000",
                 "--rival-budget", "0", "--quiet"]) == 0
    record = json.loads((out / "concept.json").read_text())
    assert len(record["parts"]) == 2 and record["settings"]["parts"] == 3
    assert record["program"].startswith(record["parts"][0])  # the first part runs first, whole
    assert "learned in 2 parts" in capsys.readouterr().out
    assert main(["learn", str(folder), "--out", str(tmp_path / "none"), "--engine", "reference", "--budget",
                 "20000", "--parts", "1", "--quiet"]) == 2  # in one part only: nothing fits
    assert not (tmp_path / "none").exists()


def test_from_few_pairs_the_other_joins_that_fit_come_back_as_rivals(two_part_pairs):
    """The question back needs the rivals of a program learned in parts: the other joins
    that fit every pair, each a different program that explains them all."""
    pairs = two_part_pairs[:2]
    got = learn(pairs, LearnSettings(budget=200_000, rival_budget=1, fresh_scenes=20), ScalarExplorer(width=1))
    assert got.found and got.parts
    rivals = [a.program for a in got.result.alternatives]
    assert rivals and got.program not in rivals and len(set(rivals)) == len(rivals)
    for program in rivals:
        for a, b in pairs:
            m = RefMachine(a).run(program)
            assert not m.failed and scenes_match(m.output_scene(), b, TAU)
    assert got.verdict is not None and got.verdict.programs[0] == 0
    # two pairs fit joins that part ways on fresh scenes (one recolours "the red object"
    # blue where another recolours the bottom one): the pairs are reported ambiguous
    assert got.ambiguous


def test_of_the_joins_that_fit_the_most_probable_is_kept():
    """Remove the left-most object, recolor the right-most: recoloring first makes more
    progress (an object brought right, against one removed), and both orders fit the
    pairs; the join kept is the one of least description length, as a whole search keeps
    the cheapest program."""
    data = dataset_for(["remove_bottom_obj"], 0, None, progress=False)
    truth, pairs = parse(REMOVE_THEN_RECOLOR), []
    for a, _ in data.pairs("remove_bottom_obj", "train"):
        m = RefMachine(a).run(truth)
        if not m.failed and scene_distance(a, m.output_scene(), TAU) == 3:  # one removed, one recolored
            pairs.append((a, m.output_scene()))
    train = pairs[:6]
    assert len(train) == 6
    assert not learn(train, LearnSettings(budget=20_000, rival_budget=0, parts=1), ScalarExplorer(width=1)).found
    got = learn(train, LearnSettings(budget=20_000, rival_budget=0), ScalarExplorer(width=1))
    assert got.found and len(got.parts) == 2
    chain = chain_for(train, LearnSettings())[0]
    orders = [parse(REMOVE_THEN_RECOLOR), parse(RECOLOR_THEN_REMOVE)]
    assert all(fits(p, train) for p in orders)
    assert join_nats(chain, got.program) == min(join_nats(chain, p) for p in orders)
    assert join_nats(chain, orders[0]) != join_nats(chain, orders[1])  # the choice is not a tie
