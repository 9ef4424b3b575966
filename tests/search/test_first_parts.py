"""First parts of more progress (`search.parts.first_parts`, `PartsSettings.further`): the
first part that brings the pairs closest can be improbable under the model, past the
candidates the search keeps near the cheapest; the searches for more progress find it.
The concept here is not among the 546: "take the central object down, then left, and
the next one up", under a model fitted on the 546 reference programs with every
`move_hand_down` followed by `move_hand_left` left out, as a model that has rarely seen
that turn."""

from __future__ import annotations

import pytest

from search.arguments import argument_logp
from search.chain import Chain
from search.model import MarkovModel, Vocabulary
from search.parts import PartsSettings, _Allowance, first_parts, progress
from vccjax.machine.instructions import OP
from vccjax.machine.program import parse
from vccjax.world.concepts import all_concepts
from vccjax.world.dataset import Dataset, build_dataset

TRUTH = parse("scene_parse; top_down_attend; move_hand_to_attended_object; grab_object; move_hand_down; "
              "move_hand_left; release_object; next_object; top_down_attend; move_hand_to_attended_object; "
              "grab_object; move_hand_up; release_object")
BUDGET = 20_000


@pytest.fixture(scope="module")
def train(tmp_path_factory):
    folder = tmp_path_factory.mktemp("first-parts")
    build_dataset(folder, seed=0, programs={"corner_then_up": TRUTH}, progress=False)
    return Dataset(folder).pairs("corner_then_up", "train")


@pytest.fixture(scope="module")
def chain() -> Chain:
    down, left = OP["move_hand_down"], OP["move_hand_left"]
    seqs = [list(p.ops) for p in all_concepts().values()
            if not any(a == down and b == left for a, b in zip(p.ops, p.ops[1:]))]
    model = MarkovModel.fit(seqs, Vocabulary().size, 1, 0.1)
    return Chain(Vocabulary(), model, argument_logp("oracle", answer=TRUTH), 0.05)


def _nats(chain: Chain, program) -> float:
    return float(chain.cheapest(program.ops, program.args)[0])


def test_the_searches_for_more_progress_find_a_first_part_past_the_kept_ones(chain, train):
    plain, _ = first_parts(chain, train, PartsSettings(budget=BUDGET, further=0), graded=True)
    best = max(progress(f, train, graded=True) for f in plain)
    assert progress(TRUTH, train, graded=True) > best  # the kept candidates stop short of it
    allowance = _Allowance(5 * BUDGET)
    got, _ = first_parts(chain, train, PartsSettings(budget=BUDGET, further=2), graded=True, allowance=allowance)
    scores = [progress(f, train, graded=True) for f in got]
    assert scores == sorted(scores, reverse=True) and scores[0] > best and min(scores) > 0
    # the most probable first part of more progress than `best`: the whole program has
    # more, so it costs no more than the whole program (one cost bin of slack for ties)
    assert _nats(chain, got[0]) <= _nats(chain, TRUTH) + chain.delta
    # charged only for what the searches covered, at most a part's budget each
    assert 3 * BUDGET <= allowance.left < 5 * BUDGET
    # every plain candidate of the most progress is still among them, past those of more
    assert all(f in got for f in plain if progress(f, train, graded=True) >= scores[-1])


def test_no_search_for_more_progress_without_allowance(chain, train):
    allowance = _Allowance(0)
    got, _ = first_parts(chain, train, PartsSettings(budget=BUDGET, further=2), graded=True, allowance=allowance)
    plain, _ = first_parts(chain, train, PartsSettings(budget=BUDGET, further=0), graded=True)
    assert got == plain and allowance.left == 0
