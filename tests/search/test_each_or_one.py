""""The square" against "every square": the learned program turned into a loop over the
attended objects, or a loop's body run once, and kept as a rival only where it explains
every pair."""

from __future__ import annotations

from search.each_or_one import for_every_object, for_the_first_object, variants
from search.learn import LearnSettings, chain_for, with_each_or_one
from search.result import Result
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.program import parse
from vccjax.machine.reference import run_reference
from vccjax.machine.scene import Scene, SceneObject, scenes_match

ONE = parse("scene_parse; set_shape_attn(square); top_down_attend; fill_color(yellow)")
EVERY = parse("scene_parse; set_shape_attn(square); loop_start; top_down_attend; fill_color(yellow); next_object; "
              "loop_end")


def _table(*objects: tuple[str, str, float, float]) -> Scene:
    return Scene(tuple(SceneObject(shape, color, x, y, 0.12) for shape, color, x, y in objects))


def test_the_part_on_the_attended_object_becomes_a_loop_and_a_loop_its_body_once():
    assert for_every_object(ONE) == EVERY
    assert for_the_first_object(EVERY) == ONE
    assert variants(ONE) == [EVERY] and variants(EVERY) == [ONE]
    # a grabbed object is dropped before the next is grabbed; the part ends at a reset
    carry = parse("scene_parse; set_color_attn(red); top_down_attend; move_hand_to_attended_object; grab_object; "
                  "move_hand_left; reset_attn; fixate(top); top_down_attend; fill_color(blue)")
    assert for_every_object(carry) == parse(
        "scene_parse; set_color_attn(red); loop_start; top_down_attend; move_hand_to_attended_object; grab_object; "
        "move_hand_left; release_object; next_object; loop_end; reset_attn; fixate(top); top_down_attend; "
        "fill_color(blue)")
    # nothing to turn: no attended object, or a part that walks the objects itself
    assert variants(parse("scene_parse; fixate(left)")) == []
    assert for_every_object(parse("scene_parse; top_down_attend; next_object; top_down_attend; fill_color(red)")) \
        is None


def test_the_loop_acts_on_every_square_where_the_program_acts_on_one():
    two = _table(("square", "red", 0.2, 0.2), ("circle", "green", 0.5, 0.5), ("square", "blue", 0.8, 0.8))
    one, every = run_reference(ONE, two).output_scene(), run_reference(EVERY, two).output_scene()
    assert sorted(o.color for o in one.objects if o.shape == "square") in (["blue", "yellow"], ["red", "yellow"])
    assert [o.color for o in every.objects if o.shape == "square"] == ["yellow", "yellow"]
    single = _table(("square", "red", 0.3, 0.3), ("circle", "green", 0.7, 0.7))
    assert scenes_match(run_reference(ONE, single).output_scene(), run_reference(EVERY, single).output_scene(),
                        DEFAULT_CONFIG.tau)


def test_a_variant_that_fits_every_pair_is_a_rival_and_one_that_does_not_is_not():
    tables = [_table(("square", "red", 0.2, 0.3), ("star", "blue", 0.7, 0.6)),
              _table(("triangle", "green", 0.3, 0.7), ("square", "blue", 0.75, 0.25))]
    pairs = [(t, run_reference(ONE, t).output_scene()) for t in tables]  # one square each: both fit
    settings = LearnSettings(args="uniform")
    chain, _ = chain_for(pairs, settings)
    nats, portions = chain.cheapest(ONE.ops, ONE.args)
    found = Result(found=True, program=ONE, text=ONE.text(), dl_nats=nats, dl_bins=chain.program_bins(portions),
                   rank=1, nodes=0, programs=0, seconds=0.0, cutoff_bins=0, budget=1)
    got = with_each_or_one(found, chain, pairs, settings)
    assert [a.program for a in got.alternatives] == [EVERY]
    assert got.alternatives[0].dl_nats == chain.cheapest(EVERY.ops, EVERY.args)[0]
    # a pair with two squares, one recoloured: "every square" no longer fits
    two = _table(("square", "red", 0.2, 0.2), ("square", "blue", 0.8, 0.8))
    pairs.append((two, run_reference(ONE, two).output_scene()))
    assert with_each_or_one(found, chain, pairs, settings).alternatives == ()
    assert with_each_or_one(found, chain, pairs[:2], LearnSettings(args="uniform", rival_budget=0)).alternatives == ()
