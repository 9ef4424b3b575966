"""Where the program learned fails on fresh scenes and a rival that fits runs, the
examples leave the concept open there: "leave it as it is" shown on tables that all hold
a star is explained as well by "grab the star", which fails on every table without one."""

from __future__ import annotations

from search.ambiguity import DOMAIN_SHARE, judge, outcomes
from vccjax.machine.program import parse
from vccjax.machine.scene import Scene, SceneObject

GRAB_STAR = parse("scene_parse; set_shape_attn(star); top_down_attend; move_hand_to_attended_object; grab_object")
NOTHING = parse("scene_parse")
RED_TOP = parse("scene_parse; fixate(top); top_down_attend; fill_color(red)")


def _inputs() -> list[Scene]:
    """Three tables, each with a star and a square (the fresh scenes draw both shapes)."""
    return [Scene((SceneObject("star", "blue", 0.25 + 0.2 * k, 0.3, 0.12),
                   SceneObject("square", "green", 0.6, 0.7 - 0.1 * k, 0.12))) for k in range(3)]


def test_a_program_that_fails_where_a_rival_runs_is_ambiguous_and_asked_there():
    inputs = _inputs()
    verdict, scenes = judge([GRAB_STAR, NOTHING], inputs, n_scenes=60, seed=1)
    first, other = outcomes(GRAB_STAR, scenes), outcomes(NOTHING, scenes)
    fails = [j for j, o in enumerate(first) if o is None]
    assert fails and all(o is not None for o in other)  # the draw has star-less tables; leaving it always runs
    assert len(fails) >= DOMAIN_SHARE * len(scenes)
    assert verdict.first_fails == len(fails)
    assert verdict.programs == [0, 1]
    assert verdict.disagree[1] == 0  # where the star is grabbed nothing moves: both leave the table as it is
    assert verdict.runs_where_first_fails[1] == len(fails)
    assert verdict.ambiguous and verdict.query in fails
    assert verdict.query_outputs[0] is None and verdict.query_outputs[1] is not None


def test_a_program_that_runs_everywhere_is_judged_by_outputs():
    """The other way round: a rival that fails where the first runs already differs there."""
    inputs = _inputs()
    verdict, scenes = judge([NOTHING, GRAB_STAR], inputs, n_scenes=60, seed=1)
    fails = sum(o is None for o in outcomes(GRAB_STAR, scenes))
    assert verdict.first_fails == 0 and verdict.runs_where_first_fails == [0, 0]
    assert verdict.disagree == [0, fails] and verdict.ambiguous
    assert verdict.query is not None and verdict.query_outputs[0] is not None and verdict.query_outputs[1] is None
    verdict, scenes = judge([NOTHING, RED_TOP], inputs, n_scenes=60, seed=1)
    differ = sum(1 for a, b in zip(outcomes(NOTHING, scenes), outcomes(RED_TOP, scenes), strict=True)
                 if [o.color for o in a.objects] != [o.color for o in b.objects])
    assert verdict.first_fails == 0 and verdict.disagree == [0, differ] and differ > 0 and verdict.ambiguous
