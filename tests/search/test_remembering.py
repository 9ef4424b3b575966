"""Remembering first parts (`search.parts.remembering`): a first part with one fixation
added, for a rest that must come back to a place the first part moved an object from.
The concept here is not among the 546: "take the central object to the pointer, and put
the next one where it was", under a model fitted on the 546 reference programs that
never use `fixate_attended_object`, as explore-compress's model before it has found one."""

from __future__ import annotations

import pytest

from search.arguments import argument_logp
from search.chain import Chain
from search.explore import Explorer
from search.model import MarkovModel, Vocabulary
from search.parts import REMEMBERING, PartsSettings, fits, learn_in_parts, remembering
from search.scalar import ScalarExplorer
from search.task import Task
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.instructions import OP
from vccjax.machine.program import Program, parse
from vccjax.machine.reference import RefMachine
from vccjax.world.concepts import all_concepts
from vccjax.world.dataset import Dataset, build_dataset

TRUTH = parse("scene_parse; top_down_attend; move_hand_to_attended_object; grab_object; fixate_attended_object; "
              "move_hand_to_pointer; release_object; next_object; top_down_attend; move_hand_to_attended_object; "
              "grab_object; move_hand_to_fixate_collision")
FIRST = parse("scene_parse; top_down_attend; move_hand_to_attended_object; grab_object; move_hand_to_pointer; "
              "release_object")
OTHER_FIRST = parse("scene_parse; top_down_attend; move_hand_to_attended_object; grab_object; move_hand_to_pointer")


@pytest.fixture(scope="module")
def data(tmp_path_factory) -> Dataset:
    folder = tmp_path_factory.mktemp("remembering")
    build_dataset(folder, seed=0, programs={"central_to_pointer_other_back": TRUTH}, progress=False)
    return Dataset(folder)


@pytest.fixture(scope="module")
def train(data):
    return data.pairs("central_to_pointer_other_back", "train")


@pytest.fixture(scope="module")
def chain() -> Chain:
    seqs = [list(p.ops) for p in all_concepts().values() if OP["fixate_attended_object"] not in p.ops]
    model = MarkovModel.fit(seqs, Vocabulary().size, 1, 0.1)
    return Chain(Vocabulary(), model, argument_logp("oracle", answer=TRUTH), 0.05)


def _state(program: Program, pairs) -> tuple:
    """Per input: (objects, pointer) made and the fovea with its history; None on failure."""
    out = []
    for a, _ in pairs:
        m = RefMachine(a, DEFAULT_CONFIG, validate=False).run(program)
        s = None if m.failed else m.output_scene()
        out.append(None if s is None else ((s.objects, s.pointer),
                                           (m.fovea.position, tuple(m.fovea.history), m.fovea.history_index)))
    return tuple(out)


def _insertions(first: Program, chain: Chain):
    """Every program that is `first` with one fixation instruction put in after scene_parse."""
    for pos in range(1, len(first.ops) + 1):
        for name in REMEMBERING:
            lp = chain.arg_logp.get(OP[name])
            for arg in [0] if lp is None else [i for i in range(len(lp)) if lp[i] > float("-inf")]:
                yield Program(first.ops[:pos] + (OP[name],) + first.ops[pos:], first.args[:pos] + (arg,) + first.args[pos:])


def test_variants_are_the_cheapest_insertion_per_new_memory_leaving_the_scenes(chain, train):
    firsts = [FIRST, OTHER_FIRST]
    got = remembering(firsts, chain, train)
    assert got
    # brute force: every single insertion the chain can spell that leaves its first
    # part's scenes as they were, the cheapest per fovea left (per first part)
    own = {_state(f, train) for f in firsts}
    best: list[dict[tuple, float]] = [{}, {}]
    for k, f in enumerate(firsts):
        scenes = tuple(None if s is None else s[0] for s in _state(f, train))
        for v in _insertions(f, chain):
            spelt, state = chain.cheapest(v.ops, v.args), _state(v, train)
            if spelt is not None and tuple(None if s is None else s[0] for s in state) == scenes and state not in own:
                best[k][state] = min(best[k].get(state, float("inf")), float(spelt[0]))
    states = [_state(v, train) for v in got]
    assert len(set(states)) == len(states)  # one per memory
    assert set(states) == set(best[0]) | set(best[1])  # none left out
    firsts_of = [0 if len(v) == len(FIRST) + 1 else 1 for v in got]
    assert firsts_of == sorted(firsts_of)  # first parts of most progress first
    for v, k, state in zip(got, firsts_of, states, strict=True):
        assert v in set(_insertions(firsts[k], chain))
        assert float(chain.cheapest(v.ops, v.args)[0]) == pytest.approx(best[k][state])
        assert k == 0 or state not in best[0]  # what the first part's variants remember is not repeated
    # the fixation after grabbing the central object, before it moves, is one of them
    assert any(v.ops[:5] == TRUTH.ops[:5] and v.ops[5:] == FIRST.ops[4:] for v in got)


def test_from_the_first_part_with_the_fixation_the_rest_is_found_and_without_it_not(chain, train):
    """Without the fixation no continuation can put the other object back: the machine has
    no memory of where the first one was. With it, the rest lies among the first thousands."""
    task = Task.from_pairs(train)
    fixating = next(v for v in remembering([FIRST], chain, train) if v.ops[:5] == TRUTH.ops[:5])
    search = Explorer(width=1)
    r = search.search(chain, task, 5_000, prefix=chain.cheapest(fixating.ops, fixating.args)[1])
    assert r.found and fits(r.program, train) and r.program.ops[: len(fixating)] == fixating.ops
    plain = search.search(chain, task, 50_000, prefix=chain.cheapest(FIRST.ops, FIRST.args)[1])
    assert not plain.found


@pytest.mark.slow
def test_the_concept_is_learned_in_parts_only_with_remembering_variants(chain, data, train):
    test = data.pairs("central_to_pointer_other_back", "test")

    def parts(n: int):
        return learn_in_parts(train, lambda p: chain, ScalarExplorer(width=1),
                              PartsSettings(max_parts=2, budget=20_000, allowance=220_000, remembering=n))[0]

    assert parts(0) is None
    got = parts(8)
    assert got is not None and fits(got.program, train)
    assert OP["fixate_attended_object"] in got.parts[0].ops
    assert sum(fits(got.program, [pair]) for pair in test) >= 0.9 * len(test)
