"""Perception accuracy on rendered scenes, and end to end through the machine.

For each seeded scene (2 to 8 objects, widths 0.04 to 0.20, a pointer half the time):
render it, parse it, and match parsed objects to true ones (same shape and colour,
centre within tau, one to one). Reports the share of true objects recovered, the share
of images with no phantom (unmatched parsed) object, pointer hits, and the errors.
"""

from __future__ import annotations

import numpy as np

from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.errors import SceneError
from vccjax.machine.scene import Scene, SceneObject
from vccjax.world.scenes import random_scene
from vccjax.vision.perception import parse_image
from vccjax.vision.render import render


def _match(true, found, tau):
    used = [False] * len(found)
    hits = 0
    for t in true:
        for j, f in enumerate(found):
            if not used[j] and f.shape == t.shape and f.color == t.color and \
                    (f.x - t.x) ** 2 + (f.y - t.y) ** 2 <= tau * tau:
                used[j] = True
                hits += 1
                break
    return hits, used.count(False)


def evaluate(n: int, style: str, seed: int = 0, size: int = 384, progress: bool = True) -> dict:
    from tqdm import tqdm

    tau = DEFAULT_CONFIG.tau
    rng = np.random.default_rng([seed, 1 if style == "varied" else 0])
    total = hits = clean = errors = ptr_total = ptr_hits = 0
    confusions: dict[str, int] = {}
    for i in tqdm(range(n), desc=style, disable=not progress):
        sc = random_scene(rng, (2, 8), widths=(0.04, 0.20), pointer=bool(rng.random() < 0.5))
        img = render(sc, size, style, seed=int(rng.integers(2**31)))
        total += len(sc.objects)
        try:
            parsed = parse_image(img)
        except SceneError as e:
            errors += 1
            confusions[f"error: {e}"[:60]] = confusions.get(f"error: {e}"[:60], 0) + 1
            continue
        h, phantoms = _match(sc.objects, parsed.objects, tau)
        hits += h
        clean += phantoms == 0
        if h < len(sc.objects):
            for t in sc.objects:
                best = min(parsed.objects, key=lambda f: (f.x - t.x) ** 2 + (f.y - t.y) ** 2)
                if (best.shape, best.color) != (t.shape, t.color):
                    k = f"{t.color} {t.shape} -> {best.color} {best.shape}"
                    confusions[k] = confusions.get(k, 0) + 1
        if sc.pointer is not None:
            ptr_total += 1
            p = parsed.pointer
            ptr_hits += p is not None and (p[0] - sc.pointer[0]) ** 2 + (p[1] - sc.pointer[1]) ** 2 <= tau * tau
    return {
        "style": style, "images": n, "objects": total, "recovered": hits / max(total, 1),
        "no_phantom_images": clean / n, "parse_errors": errors,
        "pointer_recovered": ptr_hits / max(ptr_total, 1), "pointers": ptr_total,
        "top_confusions": sorted(confusions.items(), key=lambda kv: -kv[1])[:8],
    }


def _concept_end_to_end(job: tuple[str, str, str, int, int]) -> tuple[str, int, list[int]]:
    """One concept: (name, pairs checked, indices of the test pairs that disagree)."""
    from vccjax.world.concepts import concept_names, reference_program
    from vccjax.world.dataset import Dataset
    from vccjax.machine.reference import RefMachine
    from vccjax.machine.scene import scenes_match

    folder, name, style, pairs, size = job
    ci = concept_names().index(name)  # render seeds depend on the concept, not on the subset run
    program = reference_program(name)
    test = Dataset(folder).pairs(name, "test")[:pairs]
    misses = []
    for k, (inp, out) in enumerate(test):
        img = render(inp, size, style, seed=ci * 1000 + k)
        try:
            m = RefMachine(parse_image(img)).run(program)
            ok = (not m.failed) and scenes_match(m.output_scene(), out, DEFAULT_CONFIG.tau)
        except SceneError:
            ok = False
        if not ok:
            misses.append(k)
    return name, len(test), misses


def end_to_end(
    folder: str, style: str = "varied", pairs: int = 50, concepts: list[str] | None = None,
    size: int = 384, progress: bool = True, workers: int = 1,
) -> dict:
    """For each concept's test pairs: render the input, parse it, run the reference program
    on the parsed scene, and compare with the stored (symbolic) output within tau.

    `misses` lists every concept with a disagreeing pair and those pairs' indices, so
    that a miss can be replayed (`render(inp, size, style, seed=1000 * index + k)`)."""
    from vccjax.parallel import map_with_progress
    from vccjax.world.dataset import Dataset

    names = concepts or Dataset(folder).concepts
    jobs = [(str(folder), n, style, pairs, size) for n in names]
    results = map_with_progress(_concept_end_to_end, jobs, workers, 2, f"end to end ({style})", progress)
    share = {n: 1 - len(miss) / max(total, 1) for n, total, miss in results}
    return {
        "style": style, "concepts": len(results), "pairs_per_concept": pairs,
        "concepts_at_least_99pct": sum(v >= 0.99 for v in share.values()),
        "mean_pair_agreement": float(np.mean(list(share.values()))),
        "misses": {n: miss for n, _, miss in results if miss},
    }


def touching_pair(rng: np.random.Generator) -> Scene:
    """Two objects of one colour side by side, touching (their shapes' widest points up
    to half a machine unit apart), and a third of another colour elsewhere."""
    from vccjax.machine.geometry import shape_polygon
    from vccjax.machine.instructions import COLORS, SHAPES

    def half_width(shape: str, w: float) -> float:
        return w / 2 if shape == "circle" else float(shape_polygon(shape, 0.0, 0.0, w, 1.0)[:, 0].max())

    color, other = (str(c) for c in rng.choice(COLORS, 2, replace=False))
    s1, s2, s3 = (str(s) for s in rng.choice(SHAPES, 3))
    w1, w2, w3 = rng.uniform(0.08, 0.18, 3)
    x1, y = rng.uniform(0.15, 0.35), rng.uniform(0.25, 0.45)
    x2 = x1 + half_width(s1, w1) + half_width(s2, w2) + rng.uniform(0, 0.5 / DEFAULT_CONFIG.units)
    return Scene((SceneObject(s1, color, x1, y, w1), SceneObject(s2, color, x2, y + rng.uniform(-0.03, 0.03), w2),
                  SceneObject(s3, other, rng.uniform(0.25, 0.75), 0.8, w3)), None)


def exact_scenes(n: int, style: str, size: int = 256, seed: int = 0, progress: bool = True,
                 touching: bool = False, on_object_share: float = 0.0) -> dict:
    """The share of scenes parsed exactly from pictures drawn in another style
    (`vccjax.vision.drawings`): every object found (shape, colour, centre within tau),
    no phantom object, and the pointer found (within tau) exactly when there is one.
    Half the scenes have a pointer; `on_object_share` of those have it on an object (as
    the examples of `attend_pointer` concepts do), the others keep it clear. With
    `touching`, every scene holds two objects of one colour that touch (`touching_pair`);
    our renderer's styles are drawn by `render`."""
    from tqdm import tqdm

    from vccjax.vision.drawings import draw
    from vccjax.vision.render import STYLES as RENDERED

    tau = DEFAULT_CONFIG.tau
    rng = np.random.default_rng([seed, 7, size, int(touching)])
    exact = 0
    misses: dict[str, int] = {}
    for _ in tqdm(range(n), desc=f"{style} {size}px", disable=not progress):
        pointer, on_object = rng.random() < 0.5, rng.random() < on_object_share
        if touching:
            sc = touching_pair(rng)
        else:
            sc = random_scene(rng, (2, 8), widths=(0.04, 0.20), pointer=bool(pointer),
                              pointer_on_object=bool(on_object))
        picture_seed = int(rng.integers(2**31))
        img = render(sc, size, style, picture_seed) if style in RENDERED else draw(sc, style, size, seed=picture_seed)
        try:
            parsed = parse_image(img)
        except SceneError as e:
            misses[f"error: {e}"[:50]] = misses.get(f"error: {e}"[:50], 0) + 1
            continue
        hits, phantoms = _match(sc.objects, parsed.objects, tau)
        p, q = sc.pointer, parsed.pointer
        pointer_ok = (p is None and q is None) or (
            p is not None and q is not None and (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 <= tau * tau)
        why = ("object missed" if hits < len(sc.objects) else "phantom object" if phantoms
               else "phantom pointer" if p is None and q is not None else "pointer missed" if not pointer_ok else "")
        if why:
            misses[why] = misses.get(why, 0) + 1
        else:
            exact += 1
    return {"style": style, "size": size, "touching": touching, "pointer_on_object_share": on_object_share,
            "scenes": n, "exact": exact, "exact_share": round(exact / n, 4),
            "misses": dict(sorted(misses.items(), key=lambda kv: -kv[1]))}
