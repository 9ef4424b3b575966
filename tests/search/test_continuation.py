"""Searching on from a prefix (what learning in parts continues a first part with): the
budget counts the prefix's continuations exactly (brute force), the search finds the
cheapest program that starts with the prefix, and the JAX and scalar machines visit the
same tree; the graded distance that picks such first parts, by hand."""

from __future__ import annotations

import numpy as np
import pytest

from search.arguments import argument_logp
from search.chain import OUTSIDE, Chain, cutoff_for_budget
from search.explore import Explorer, Task
from search.model import MarkovModel, Vocabulary
from search.learn import LearnSettings, chain_for
from search.parts import PartsSettings, fits, gains, graded_distance, learn_in_parts
from search.scalar import ScalarExplorer
from vccjax.machine.instructions import OP
from vccjax.machine.program import parse
from vccjax.machine.scene import Scene, SceneObject, aligned_size, matching_size
from vccjax.world.concepts import all_concepts, reference_program
from vccjax.world.dataset import Dataset, build_dataset, dataset_for

CONCEPT = "move_left_obj_to_bottom"  # scene_parse; fixate(left); top_down_attend; ... move_hand_down; release_object
TAU = 0.05


@pytest.fixture(scope="module")
def chain() -> Chain:
    """The atoms' model fitted on the 546 reference programs, the concept's own arguments."""
    model = MarkovModel.fit([list(p.ops) for p in all_concepts().values()], Vocabulary().size, 1, 0.1)
    return Chain(Vocabulary(), model, argument_logp("oracle", answer=reference_program(CONCEPT)), 0.05)


@pytest.fixture(scope="module")
def task() -> Task:
    return Task.from_pairs(dataset_for([CONCEPT], 0, None, progress=False).pairs(CONCEPT, "train")[:3])


def _continuations(chain: Chain, last: int, syn: int, bound: int) -> list[int]:
    """The cost in bins of every syntax-valid continuation (the empty one included where
    the prefix may end) from (last token, syntax state), up to `bound`, by recursion."""
    costs: list[int] = []

    def grow(last: int, syn: int, cost: int) -> None:
        if syn == OUTSIDE and cost + chain.trans_bins[last, chain.end] <= bound:
            costs.append(int(cost + chain.trans_bins[last, chain.end]))
        for z in range(chain.n_portions):
            t, nxt = int(chain.tok[z]), int(chain.next_syn[chain.tok[z], syn])
            c = cost + int(chain.trans_bins[last, t] + chain.argbins[z])
            if nxt >= 0 and c <= bound:
                grow(t, nxt, c)

    grow(last, syn, 0)
    return costs


@pytest.mark.parametrize("after", ["scene_parse", "grab_object", "loop_start"])
def test_the_budget_from_a_prefix_counts_its_continuations(chain, after):
    syn = 2 if after == "loop_start" else OUTSIDE  # inside a loop nothing may end yet
    root = (OP[after], syn)  # the atoms come first among the tokens, in op order
    cutoff, table = cutoff_for_budget(chain, 3000, root)
    costs = np.array(_continuations(chain, *root, cutoff))
    np.testing.assert_array_equal(table, [(costs <= b).sum() for b in range(cutoff + 1)])
    assert table[-1] >= 3000 and (cutoff == 0 or table[-2] < 3000)
    # a table from the start is another table: the root is part of what is cached
    assert not np.array_equal(cutoff_for_budget(chain, 3000)[1][: cutoff + 1], table)


def test_a_search_from_a_prefix_finds_the_cheapest_program_that_starts_with_it(chain, task):
    whole = ScalarExplorer(width=1).search(chain, task, 20_000)
    assert whole.found
    portions = chain.cheapest(whole.program.ops, whole.program.args)[1]
    jax_search = Explorer(width=1)
    for k in range(1, len(portions)):
        on_ref = ScalarExplorer(width=1).search(chain, task, 20_000, prefix=portions[:k])
        on_jax = jax_search.search(chain, task, 20_000, prefix=portions[:k])
        # the cheapest program through the prefix is the cheapest of all, which starts with
        # it; its cost and rank are the continuation's
        assert on_ref.found and on_ref.program == whole.program
        assert on_ref.dl_bins == chain.program_bins(portions) - _prefix_bins(chain, portions[:k])
        assert on_ref.rank <= whole.rank
        # both machines visit the same tree
        assert (on_jax.program, on_jax.programs, on_jax.nodes) == (on_ref.program, on_ref.programs, on_ref.nodes)
    # from the whole program, the best continuation is to end: rank 1
    done = ScalarExplorer(width=1).search(chain, task, 20_000, prefix=portions)
    assert done.found and done.program == whole.program and done.rank == 1


def _prefix_bins(chain: Chain, portions: list[int]) -> int:
    last, total = chain.end, 0
    for z in portions:
        total += int(chain.trans_bins[last, chain.tok[z]] + chain.argbins[z])
        last = int(chain.tok[z])
    return total


def test_a_prefix_that_fails_leaves_nothing_to_search(chain, task):
    z_grab = next(z for z in range(chain.n_portions) if chain.ops[z] == (OP["grab_object"],))
    z_parse = next(z for z in range(chain.n_portions) if chain.ops[z] == (OP["scene_parse"],))
    for searcher in (ScalarExplorer(width=1), Explorer(width=1)):  # nothing held, nothing attended: it fails
        r = searcher.search(chain, task, 1000, prefix=[z_parse, z_grab])
        assert not r.found and r.programs == 0


def _obj(x: float, y: float, color: str = "red") -> SceneObject:
    return SceneObject("square", color, x, y, 0.1)


def test_an_object_in_its_outputs_row_or_column_counts_half():
    goal = Scene((_obj(0.1, 0.9), _obj(0.5, 0.5, "blue")))
    start = Scene((_obj(0.6, 0.2), _obj(0.5, 0.5, "blue")))  # red: neither row nor column yet
    down = Scene((_obj(0.6, 0.9), _obj(0.5, 0.5, "blue")))  # red: in its row
    there = goal
    assert [matching_size(s, goal, TAU) for s in (start, down, there)] == [1, 1, 2]
    assert [aligned_size(s, goal, TAU) for s in (start, down, there)] == [1, 2, 2]
    # in half objects: 2 objects per scene, an exact pair takes 4 off, an aligned one 2
    assert [graded_distance(s, goal, TAU) for s in (start, down, there)] == [4, 2, 0]
    pairs = [(start, goal)]
    assert gains([down], pairs, TAU) is None  # not progress by whole objects
    assert gains([down], pairs, TAU, graded=True) == [2]
    assert gains([Scene((_obj(0.6, 0.9, "green"), _obj(0.5, 0.5, "blue")))], pairs, TAU, graded=True) is None


POINTED_TO_CORNER = ("scene_parse; attend_pointer; move_hand_to_attended_object; grab_object; move_hand_down; "
                     "move_hand_left; release_object")


def test_a_held_object_is_taken_on_by_a_continuation_where_a_fresh_rest_cannot(tmp_path):
    """Take the pointed object to the lower-left corner: past any budget whole (the
    library rarely saw the pointer before a move), and no first part places an object
    whole. A first part judged by graded progress takes it down, still held; a rest
    searched from a fresh scene_parse of what it made cannot pick the held object out
    again, while the continuation from the machine state it leaves is two tokens away."""
    build_dataset(tmp_path, seed=0, programs={"pointed_to_corner": parse(POINTED_TO_CORNER)}, progress=False)
    data = Dataset(tmp_path)
    train, test = data.pairs("pointed_to_corner", "train"), data.pairs("pointed_to_corner", "test")
    settings = LearnSettings()
    chain = chain_for(train, settings)[0]
    truth = chain.cheapest(parse(POINTED_TO_CORNER).ops, parse(POINTED_TO_CORNER).args)
    bins = chain.program_bins(truth[1])
    assert chain.count_table(budget=10**9, max_bins=bins)[-1] >= 10**9  # a billion programs cost no more

    def parts(continuations: bool):
        return learn_in_parts(train, lambda p: chain_for(p, settings)[0], ScalarExplorer(width=1),
                              PartsSettings(budget=20_000, allowance=200_000, continuations=continuations))[0]

    assert parts(False) is None
    got = parts(True)
    assert got is not None and len(got.parts) == 2
    first = got.parts[0]
    assert OP["grab_object"] in first.ops and OP["release_object"] not in first.ops  # it ends holding the object
    assert got.program.ops[: len(first)] == first.ops and len(got.parts[1]) <= 3
    assert fits(got.program, train)
    # on pairs it never saw: right nearly always (the pairs cannot tell `fixate_pointer;
    # top_down_attend`, the object nearest the pointer, from `attend_pointer`)
    assert sum(fits(got.program, [pair]) for pair in test) >= 0.9 * len(test)
