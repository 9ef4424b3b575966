"""Learning in parts: a concept whose program lies past the budget, learned as a first
part that brings every example closer to its output, then the rest from there.

A user's concept often does one thing to one object and another to a second ("recolor
the top object red and the bottom one blue"). The whole program can rank far past the
budget even when each half is among the first thousand programs, because the model
learned on the 546 rarely saw the join. When the search finds nothing, `learn_in_parts`:

1. searches for *first parts*: programs under which every example's scene gets strictly
   closer to its output (`vccjax.machine.scene.scene_distance`: objects still unpaired
   with an output object drop; no example gets farther or loses an object its output
   keeps: `gains`), one per distinct effect on the examples, the most progress first;
2. runs each first part on the inputs and searches for the rest on the pairs (what the
   first part made, the output), recursively up to `max_parts` parts;
3. joins the parts (the rest's `scene_parse` dropped, a `reset_attn` between them where
   the join needs it) and keeps the join only if the reference machine runs it right on
   every given pair: a program learned in parts is checked like any other;
4. of the joins that fit, keeps the most probable under the whole pairs' chain (least
   description length), as a whole search keeps the cheapest program that fits: every
   first part is tried, since the one of most progress need not lead to the cheapest
   join (recolor-then-remove makes more progress than remove-then-recolor, and the
   two can fit the same pairs).

When no join fits, the search goes on from where a first part leaves the machine: first
parts are then judged by a graded measure (an object brought into its output's row or
column counts half: `graded_distance`), and what follows each is searched as a
*continuation* of it (`search.dfs.depth_first` with a prefix), from the machine state it
leaves, the object still held and attended. "Take the pointed object down, then left"
is then the first part and two more tokens, where a rest searched from a fresh
`scene_parse` of the scenes made could not pick the held object out again.

Where no continuation fits either, the first parts are tried once more with one
fixation added (`remembering`): the same scenes made, the fovea left on a place the rest
can come back to. "Move the central object right, then put another where it was" is
then the first part with `fixate_attended_object` before the move, and five tokens on.

The first parts are judged on the host by the scalar reference (`ScalarBackend` with
another judge); the rest is an ordinary search on the caller's searcher. Each search
covers a tenth of `vcc learn`'s budget (a remembering variant's a tenth of that), and
all of them together at most 1.3 budgets (`parts_settings`), so parts cost about as much
as the plain search they follow.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence

import numpy as np

from search.ambiguity import outcomes
from search.chain import Chain
from search.dfs import Alternatives
from search.explore import Searcher
from search.result import program_of
from search.scalar import ScalarBackend
from search.task import Task
from vccjax.errors import SceneError
from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.instructions import OP
from vccjax.machine.program import Program
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, aligned_size, matching_size, scene_distance, scenes_match


@dataclasses.dataclass(frozen=True)
class PartsSettings:
    max_parts: int = 3  # parts a program may be learned in (1: never in parts)
    budget: int = 50_000  # each part's search: its budget (the most probable programs it covers)
    allowance: int = 500_000  # the parts' searches' budgets added up, at most
    tries: int = 4  # first parts tried, one per distinct effect on the examples
    candidates: int = 16  # first parts kept by their search, of which the `tries` of most progress
    margin_nats: float = 8.0  # first parts (and rests' rivals) at most this much less probable than the cheapest
    rivals: int = 0  # other fitting joins to keep, for the question back (0: stop at the first fit)
    continuations: bool = True  # when no join fits, search on from graded first parts' machine states
    remembering: int = 8  # then first parts with a fixation added (`remembering`), each searched on a tenth of `budget`
    further: int = 2  # searches for a first part of more progress than any kept (`first_parts`)


def parts_settings(budget: int, max_parts: int, rivals: int = 0) -> PartsSettings:
    """A part's search a tenth of the budget; all parts of a concept at most 1.3 budgets:
    the budget, one part's more for the remembering variants, and one for each of the
    two searches for a first part of more progress (first parts, then graded ones)."""
    part = max(1, budget // 10)
    return PartsSettings(max_parts=max_parts, budget=part, allowance=budget + 3 * part, rivals=rivals)


@dataclasses.dataclass(frozen=True)
class InParts:
    """A program learned in parts, and the parts (each as its own program)."""

    program: Program
    parts: tuple[Program, ...]
    rivals: tuple[Program, ...] = ()  # other joins that fit every pair (`PartsSettings.rivals`)


class ProgressBackend(ScalarBackend):
    """The scalar search whose judge accepts a program that brings the examples closer
    to their outputs (fewer objects left unpaired; `graded`: also counting objects
    brought into their row or column): no example farther, some closer. (Not every
    example closer: where the first part's change is already made, as a top object
    already red, it rightly does nothing.)"""

    def __init__(self, cfg: VCCConfig = DEFAULT_CONFIG, graded: bool = False, above: int = 0):
        super().__init__(cfg)
        self.graded = graded
        self.above = above  # accept only more progress than this (`gains` summed)

    def solves(self, machines: list[RefMachine], task: Task) -> bool:
        made = gains([m.output_scene() for m in machines], task.pairs, self.cfg.tau, self.graded)
        return made is not None and sum(made) > self.above


def graded_distance(a: Scene, b: Scene, tau: float) -> int:
    """`scene_distance` in half objects, where an object paired with its output's only in
    its row or column (`aligned_size`) counts half done: a move toward a corner that has
    reached the bottom edge is progress."""
    return 2 * (len(a.objects) + len(b.objects)) - 2 * (matching_size(a, b, tau) + aligned_size(a, b, tau))


def gains(made: Sequence[Scene | None], pairs: Sequence[tuple[Scene, Scene]], tau: float,
          graded: bool = False) -> list[int] | None:
    """Per pair, how much closer `made` is to the output than the input was (`graded`:
    by `graded_distance`), or None unless the scenes made are progress: none failed,
    none farther, some closer, and none with fewer objects than its output (no
    instruction adds an object back, so a removal there could never be made good:
    removing a misplaced object is not progress)."""
    if any(m is None for m in made):
        return None
    if any(len(m.objects) < len(b.objects) for m, (_, b) in zip(made, pairs, strict=True)):
        return None
    distance = graded_distance if graded else scene_distance
    out = [distance(a, b, tau) - distance(m, b, tau) for m, (a, b) in zip(made, pairs, strict=True)]
    return out if min(out) >= 0 and sum(out) > 0 else None


def progress(program: Program, pairs: Sequence[tuple[Scene, Scene]], cfg: VCCConfig = DEFAULT_CONFIG,
             graded: bool = False) -> int:
    """Objects brought right over all pairs (`gains` summed; 0 when not progress)."""
    made = gains(outcomes(program, [a for a, _ in pairs], cfg), pairs, cfg.tau, graded)
    return 0 if made is None else sum(made)


def first_parts(chain: Chain, pairs: Sequence[tuple[Scene, Scene]], settings: PartsSettings,
                cfg: VCCConfig = DEFAULT_CONFIG, graded: bool = False,
                allowance: _Allowance | None = None) -> tuple[list[Program], int]:
    """(first parts, most progress first then most probable; complete programs judged):
    programs that bring the pairs closer to their outputs (`ProgressBackend`), one per
    distinct effect on the pairs (two that make the same scenes leave the same rest).

    The search keeps the `candidates` most probable within `margin_nats` of the
    cheapest; the first part of most progress can lie past them ("take it down, then
    left" where the model has rarely seen down followed by left). Then up to `further`
    searches look for the most probable first part of more progress than any kept, each
    within the part's budget and charged to `allowance` for the programs it covered."""
    inputs = [a for a, _ in pairs]

    def effect(path) -> tuple:
        made = outcomes(program_of(chain, [int(x) for x in path if x >= 0]), inputs, cfg)
        return tuple((None if m is None else (m.objects, m.pointer)) for m in made)

    task = Task.from_pairs(pairs, cfg)
    searcher = Searcher(ProgressBackend(cfg, graded), width=1)
    alternatives = Alternatives(int(math.ceil(settings.margin_nats / chain.delta)), settings.candidates,
                                settings.budget, effect)
    r = searcher.search(chain, task, settings.budget, alternatives=alternatives)
    if not r.found:
        return [], r.programs
    judged = r.programs
    found = [r.program] + [a.program for a in r.alternatives]
    score = {p: progress(p, pairs, cfg, graded) for p in found}
    for _ in range(settings.further):
        if allowance is not None and not allowance.take(settings.budget):
            break
        more = Searcher(ProgressBackend(cfg, graded, above=max(score.values())), width=1)
        r = more.search(chain, task, settings.budget)
        judged += r.programs
        if allowance is not None and r.found:
            allowance.give_back(settings.budget - min(settings.budget, r.rank))
        if not r.found:
            break
        found.append(r.program)
        score[r.program] = progress(r.program, pairs, cfg, graded)
    order = sorted(range(len(found)), key=lambda i: (-score[found[i]], i))
    return [found[i] for i in order][: settings.tries], judged


def joins(first: Program, rest: Program) -> list[Program]:
    """The two ways to run `rest` after `first`: straight on, and after `reset_attn` (the
    rest was learned from a fresh machine, with nothing attended)."""
    tail_ops, tail_args = rest.ops[1:], rest.args[1:]  # every program starts with scene_parse
    reset = OP["reset_attn"]
    return [Program(first.ops + tail_ops, first.args + tail_args),
            Program(first.ops + (reset,) + tail_ops, first.args + (0,) + tail_args)]


def fits(program: Program, pairs: Sequence[tuple[Scene, Scene]], cfg: VCCConfig = DEFAULT_CONFIG) -> bool:
    made = outcomes(program, [a for a, _ in pairs], cfg)
    return all(m is not None and scenes_match(m, b, cfg.tau) for m, (_, b) in zip(made, pairs, strict=True))


class _Allowance:
    """What the parts' searches may still cover, shared down the recursion."""

    def __init__(self, left: int):
        self.left = left

    def take(self, budget: int) -> bool:
        if self.left < budget:
            return False
        self.left -= budget
        return True

    def give_back(self, unused: int) -> None:
        """Return what a search took but did not cover (it stopped at what it found)."""
        self.left += unused


def learn_in_parts(pairs: Sequence[tuple[Scene, Scene]], chain_of: Callable[[Sequence[tuple[Scene, Scene]]], Chain],
                   searcher: Searcher, settings: PartsSettings, cfg: VCCConfig = DEFAULT_CONFIG,
                   log: Callable[[str], None] | None = None,
                   allowance: _Allowance | None = None) -> tuple[InParts | None, int]:
    """(a program for `pairs` in at most `settings.max_parts` parts or None, complete
    programs judged). `chain_of` gives the search's chain for a set of pairs (its
    argument beliefs come from them). Every search, first parts or rest, has
    `settings.budget`; they stop when `settings.allowance` is spent.

    With `settings.rivals`, the search goes on past the first fit: the rests are searched
    with their own rivals, every first part is tried, and up to `rivals` other joins that
    fit every pair are kept, for the question back (few pairs fit many joins)."""
    top = allowance is None  # continuations are searched at the top only
    allowance = allowance or _Allowance(settings.allowance)
    if settings.max_parts < 2 or not allowance.take(settings.budget):
        return None, 0
    whole = chain_of(pairs)
    firsts, judged = first_parts(whole, pairs, settings, cfg, allowance=allowance)
    fitting: list[tuple[float, Program, tuple[Program, ...]]] = []  # (nats, join, parts), in the order found
    for first in firsts:
        if not allowance.take(settings.budget):
            break
        made = outcomes(first, [a for a, _ in pairs], cfg)
        rest_pairs = [(m, b) for m, (_, b) in zip(made, pairs, strict=True)]
        try:
            task = Task.from_pairs(rest_pairs, cfg)
        except SceneError:  # a scene the machine made that its loader refuses: not a start to learn from
            continue
        if log:
            log(f"first part {first.text()}: the rest from what it makes")
        chain = chain_of(rest_pairs)
        alternatives = (Alternatives(int(math.ceil(settings.margin_nats / chain.delta)), settings.rivals,
                                     settings.budget) if settings.rivals else None)
        rest = searcher.search(chain, task, settings.budget, alternatives=alternatives)
        judged += rest.programs
        tails: list[tuple[Program, tuple[Program, ...]]] = []
        if rest.found:
            tails = [(p, (p,)) for p in [rest.program] + [a.program for a in rest.alternatives]]
        elif settings.max_parts > 2:
            deeper, n = learn_in_parts(rest_pairs, chain_of, searcher,
                                       dataclasses.replace(settings, max_parts=settings.max_parts - 1), cfg, log,
                                       allowance)
            judged += n
            if deeper is not None:
                tails = [(deeper.program, deeper.parts)] + [(p, (p,)) for p in deeper.rivals]
        for tail, tail_parts in tails:
            joined = next((j for j in joins(first, tail) if fits(j, pairs, cfg)), None)
            if joined is not None and all(joined != f[1] for f in fitting):
                fitting.append((join_nats(whole, joined), joined, (first,) + tail_parts))
    if not fitting and top and settings.continuations and allowance.take(settings.budget):
        found, n = continued(whole, pairs, searcher, settings, allowance, cfg, log)
        judged += n
        fitting += found
    if not fitting:
        return None, judged
    fitting.sort(key=lambda f: f[0])  # stable: equal lengths keep the order found
    (_, program, parts), rest_fits = fitting[0], fitting[1:]
    return InParts(program, parts, tuple(f[1] for f in rest_fits[: settings.rivals])), judged


def continued(whole: Chain, pairs: Sequence[tuple[Scene, Scene]], searcher: Searcher, settings: PartsSettings,
              allowance: _Allowance, cfg: VCCConfig = DEFAULT_CONFIG, log: Callable[[str], None] | None = None
              ) -> tuple[list[tuple[float, Program, tuple[Program, ...]]], int]:
    """([(nats, program, (first part, what follows))] that fit every pair, complete
    programs judged): first parts judged by graded progress (their search already
    taken from `allowance`), each continued by a search of the programs that start with
    it (`Searcher.search` with a prefix), on the whole pairs and their chain. Where none
    fits, the first parts' `remembering` variants are continued the same way, each on a
    tenth of a part's budget."""
    firsts, judged = first_parts(whole, pairs, settings, cfg, graded=True, allowance=allowance)
    task = Task.from_pairs(pairs, cfg)
    fitting: list[tuple[float, Program, tuple[Program, ...]]] = []

    def go_on(first: Program, budget: int) -> None:
        nonlocal judged
        spelt = whole.cheapest(first.ops, first.args)
        if spelt is None or not allowance.take(budget):
            return
        if log:
            log(f"first part {first.text()}: what follows, from the machine state it leaves")
        alternatives = (Alternatives(int(math.ceil(settings.margin_nats / whole.delta)), settings.rivals,
                                     budget) if settings.rivals else None)
        r = searcher.search(whole, task, budget, alternatives=alternatives, prefix=spelt[1])
        judged += r.programs
        for p in ([r.program] + [a.program for a in r.alternatives]) if r.found else []:
            if fits(p, pairs, cfg) and all(p != f[1] for f in fitting):
                n = len(first.ops)  # the parts: the first, and what follows it (if anything)
                parts = (first,) + ((Program(p.ops[n:], p.args[n:]),) if len(p) > n else ())
                fitting.append((join_nats(whole, p), p, parts))

    for first in firsts:
        go_on(first, settings.budget)
    if not fitting and settings.remembering:
        for variant in remembering(firsts, whole, pairs, cfg)[: settings.remembering]:
            go_on(variant, max(1, settings.budget // 10))
    return fitting, judged


REMEMBERING = ("fixate_attended_object", "fixate_pointer", "fixate_previous", "fixate_next", "fixate")


def remembering(firsts: Sequence[Program], chain: Chain, pairs: Sequence[tuple[Scene, Scene]],
                cfg: VCCConfig = DEFAULT_CONFIG) -> list[Program]:
    """The first parts with one fixation added, where it leaves the scenes as they were
    and the fovea (the machine's only memory of a place) elsewhere: cheapest first under
    `chain`, one per distinct memory left. "Move the central object, then put another
    where it was" needs its first part to fixate the object before moving it; that
    part makes the same scenes as the cheaper one without the fixation, so the search
    for first parts, which tells them apart by their scenes, never keeps it. In the
    first parts' order (most progress first), each one's variants cheapest first."""
    inputs = [a for a, _ in pairs]
    own = [_memory(f, inputs, cfg) for f in firsts]
    found: list[tuple[int, float, int, Program, tuple]] = []
    for k, first in enumerate(firsts):
        scenes = tuple(None if m is None else m[0] for m in own[k])
        for pos in range(1, len(first.ops) + 1):
            for name in REMEMBERING:
                lp = chain.arg_logp.get(OP[name])
                for arg in ([0] if lp is None else [int(i) for i in np.nonzero(np.isfinite(lp))[0]]):
                    v = Program(first.ops[:pos] + (OP[name],) + first.ops[pos:],
                                first.args[:pos] + (arg,) + first.args[pos:])
                    spelt = chain.cheapest(v.ops, v.args)
                    memory = () if spelt is None else _memory(v, inputs, cfg)
                    if spelt is not None and tuple(None if m is None else m[0] for m in memory) == scenes:
                        found.append((k, float(spelt[0]), len(found), v, memory))
    seen = set(own)  # a variant remembering nothing new is its first part
    out = []
    for *_, v, memory in sorted(found, key=lambda f: f[:3]):
        if memory not in seen:
            seen.add(memory)
            out.append(v)
    return out


def _memory(program: Program, inputs: Sequence[Scene], cfg: VCCConfig) -> tuple:
    """Per input, (objects and pointer made, fovea and its history), or None where it fails."""
    out = []
    for s in inputs:
        m = RefMachine(s, cfg, validate=False).run(program)
        f = m.fovea
        scene = m.output_scene() if not m.failed else None
        out.append(None if scene is None else ((scene.objects, scene.pointer),
                                               (f.position, tuple(f.history), f.history_index)))
    return tuple(out)


def join_nats(chain: Chain, program: Program) -> float:
    """A join's description length under `chain` (its cheapest spelling; inf where the
    chain rules out an argument it uses)."""
    spelt = chain.cheapest(program.ops, program.args)
    return math.inf if spelt is None else float(spelt[0])
