"""Whether a few examples leave a concept ambiguous, and which scene would settle it.

Several programs may explain every given pair. They are run on fresh scenes drawn like
the user's inputs (the same shapes and colours, as many objects or one more, as wide, a
pointer when the inputs have one); programs that give the same outcome on every fresh scene
behave alike and count as one. The examples are ambiguous when a program that behaves
unlike the first one found gives another output on a fresh scene where the first runs
(on at least `min_scenes` of them, so a rare tie of distances is not an alarm), or when
the first fails on a share of the fresh scenes (`DOMAIN_SHARE`) where another runs: three
"leave it as it is" pairs of scenes that all hold a star are explained as well by "grab
the star", which fails on every table without one. The question put back is the fresh
scene whose answer most probably leaves the right program as the cheapest that fits
(`judge`): the user answers it by adding that input with the output they mean as one
more pair.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from vccjax.errors import SceneError
from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.program import Program
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, scenes_match


TEMPER_NATS = 3.0  # description lengths are overconfident (docs/learn.md, "Ambiguity")
# Fresh scenes hold as many objects as the inputs, or one more (up to this many): what a
# concept does with one object more is what a few small examples most often leave open.
MORE_OBJECTS_UP_TO = 8
# The first program failing where a rival runs is ambiguity once it fails on this share
# of the fresh scenes: a fitting program that fails on a tenth of the tables like the
# user's leaves open what the concept does there; a rarer failure (a grab that finds no
# object at a corner case) is not worth a question.
DOMAIN_SHARE = 0.1


@dataclasses.dataclass(frozen=True)
class SceneStyle:
    """What fresh scenes share with the user's inputs (as many objects or one more)."""

    objects: tuple[int, int]
    widths: tuple[float, float]
    shapes: tuple[str, ...]
    colors: tuple[str, ...]
    pointer: bool
    pointer_on_object: bool  # the inputs' pointers lie on objects (as `attend_pointer` needs)

    @classmethod
    def of(cls, inputs: Sequence[Scene], cfg: VCCConfig = DEFAULT_CONFIG) -> SceneStyle:
        counts = [len(s.objects) for s in inputs]
        widths = [o.width for s in inputs for o in s.objects]
        pointed = [s for s in inputs if s.pointer is not None]
        most = max(max(counts), min(max(counts) + 1, MORE_OBJECTS_UP_TO))
        return cls((min(counts), most), (min(widths), max(widths)),
                   tuple(sorted({o.shape for s in inputs for o in s.objects})),
                   tuple(sorted({o.color for s in inputs for o in s.objects})),
                   bool(pointed), bool(pointed) and all(_points_at_an_object(s, cfg) for s in pointed))


def _points_at_an_object(scene: Scene, cfg: VCCConfig) -> bool:
    """Whether an object's mask holds the pointer's pixel (the rule `attend_pointer` reads)."""
    from vccjax.machine.geometry import object_pixels
    from vccjax.machine.scene import to_units

    m = RefMachine(scene, cfg, validate=False)
    pixel = m.pixel_of(m.pointer)
    for o in scene.objects:
        rows, cols = object_pixels(o.shape, o.width, to_units(o.x, cfg), to_units(o.y, cfg), cfg)
        if pixel in set(zip(rows.tolist(), cols.tolist())):
            return True
    return False


def fresh_scenes(inputs: Sequence[Scene], n: int, seed: int, cfg: VCCConfig = DEFAULT_CONFIG) -> list[Scene]:
    """`n` seeded random scenes like `inputs` (`SceneStyle`); a draw that cannot be
    placed is drawn again, and fewer are returned only if most draws fail."""
    from vccjax.world.scenes import random_scene

    style = SceneStyle.of(inputs, cfg)
    rng = np.random.default_rng([seed, 0xA1B])
    scenes: list[Scene] = []
    for _ in range(4 * n):
        if len(scenes) == n:
            break
        try:
            scenes.append(random_scene(rng, style.objects, widths=style.widths, pointer=style.pointer, cfg=cfg,
                                       shapes=style.shapes, colors=style.colors,
                                       pointer_on_object=style.pointer_on_object))
        except SceneError:
            continue
    return scenes


def outcomes(program: Program, scenes: Sequence[Scene], cfg: VCCConfig = DEFAULT_CONFIG) -> list[Scene | None]:
    """The program's output on each scene (None where it fails), on the reference."""
    out = []
    for s in scenes:
        m = RefMachine(s, cfg, validate=False).run(program)
        out.append(None if m.failed else m.output_scene())
    return out


def same(a: Scene | None, b: Scene | None, tau: float) -> bool:
    return (a is None and b is None) or (a is not None and b is not None and scenes_match(a, b, tau))


def groups_of(outputs: Sequence[Scene | None], tau: float) -> list[list[int]]:
    """Indices of `outputs` grouped by outcome (one group per distinct output, failing
    included), in order of first appearance."""
    groups: list[list[int]] = []
    for i, o in enumerate(outputs):
        for g in groups:
            if same(o, outputs[g[0]], tau):
                g.append(i)
                break
        else:
            groups.append([i])
    return groups


@dataclasses.dataclass
class Verdict:
    """The programs that behave differently (the first found first), how many fresh
    scenes each parts from the first on, and the question to ask."""

    programs: list[int]  # indices into the candidates: one per distinct behaviour
    disagree: list[int]  # per kept program: fresh scenes where the first runs and it differs
    runs_where_first_fails: list[int]  # per kept program: fresh scenes where the first fails and it runs
    first_fails: int  # fresh scenes where the first program fails
    scenes: int  # fresh scenes drawn
    ambiguous: bool
    query: int | None  # index of the fresh scene to ask about
    query_outputs: list[Scene | None]  # each kept program's outcome on it
    answers: list[list[int]]  # positions in `programs` grouped by their outcome on the query


def judge(candidates: Sequence[Program], inputs: Sequence[Scene], n_scenes: int = 100, seed: int = 0,
          min_scenes: int = 2, cfg: VCCConfig = DEFAULT_CONFIG,
          nats: Sequence[float] | None = None) -> tuple[Verdict, list[Scene]]:
    """Group `candidates` (the first is the program learned; `nats`, their description
    lengths) by behaviour on fresh scenes like `inputs`, decide whether the examples are
    ambiguous, and pick the query: the fresh scene whose answer most probably leaves the
    right program as the cheapest one that fits, that is with the largest sum, over its
    outcome groups, of the group's most probable member; ties go to a scene the first runs
    on, then to fewer objects. The query is a scene the first program runs on, or, where
    its failures make the examples ambiguous, any fresh scene (a failure is then one
    outcome among the others).

    The answer keeps one outcome group, and learning again keeps its cheapest program; if
    the right program is in that group, it is kept exactly when it is the group's most
    probable member. Each behaviour is weighted by exp(-description length / TEMPER_NATS):
    a description length sums many smoothed transitions and is overconfident, and with
    the untempered weights the question went to the first program's nearest variants (a
    nat or two apart) rather than to a rival that reads the pictures otherwise."""
    scenes = fresh_scenes(inputs, n_scenes, seed, cfg)
    tau = cfg.tau
    runs = [outcomes(p, scenes, cfg) for p in candidates]
    kept: list[int] = []
    for i, run in enumerate(runs):
        if not any(all(same(x, y, tau) for x, y in zip(run, runs[k], strict=True)) for k in kept):
            kept.append(i)
    first = runs[0]
    disagree = [sum(1 for j, o in enumerate(first) if o is not None and not same(o, runs[k][j], tau)) for k in kept]
    elsewhere = [sum(1 for j, o in enumerate(first) if o is None and runs[k][j] is not None) for k in kept]
    by_output = any(d >= min_scenes for d in disagree[1:])
    by_domain = any(e >= max(min_scenes, DOMAIN_SHARE * len(scenes)) for e in elsewhere[1:])
    ambiguous = by_output or by_domain
    dl = np.asarray(nats, float) if nats is not None else np.zeros(len(candidates))
    weight = np.exp(-(dl - dl.min()) / TEMPER_NATS)  # the model's belief in each, tempered
    query = None
    if ambiguous:
        def rank(j: int) -> tuple:
            groups = groups_of([runs[k][j] for k in kept], tau)
            kept_right = sum(max(weight[kept[i]] for i in g) for g in groups)
            return (-kept_right, first[j] is None, len(scenes[j].objects), j)  # at a tie, one it runs on

        usable = [j for j in range(len(scenes)) if first[j] is not None or by_domain]
        query = min(usable, key=rank)
    outs = [runs[k][query] for k in kept] if query is not None else []
    return Verdict(kept, disagree, elsewhere, sum(o is None for o in first), len(scenes), ambiguous, query, outs,
                   groups_of(outs, tau) if outs else []), scenes
