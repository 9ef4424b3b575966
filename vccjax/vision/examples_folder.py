"""A user's examples of a concept, as a folder of before/after pairs.

`<k>_in.json` / `<k>_out.json` are scenes as `vcc run --scene` reads them;
`<k>_in.png` / `<k>_out.png` (or .jpg) are pictures parsed by `parse_image` (a schematic
drawn by `vcc`, a drawing with flat colours, or a rectified camera image). A pair may mix
the two. Pairs are taken in the natural order of their keys (2 before 10). Files whose
names start with a dot are skipped; any other file that is not half of a pair is an
error, so a misnamed file is never silently left out.

Every pair is checked before any search: both scenes valid, and the output one the
machine can make from the input (docs/vcc.md section 7: objects keep their shape, and
are moved, recoloured or removed, never made).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from vccjax.errors import SceneError, VCCError
from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.scene import Scene

PAIR_FILE = re.compile(r"^(?P<key>.+)_(?P<side>in|out)\.(?P<ext>json|png|jpg|jpeg)$", re.IGNORECASE)
IMAGE_EXTS = ("png", "jpg", "jpeg")


MAX_SIDE = 8192  # pixels a side: a scene is parsed at a few hundred


def read_image(path: str | Path) -> np.ndarray:
    """An image file as RGB uint8, or a one-line error naming the file."""
    import cv2

    path = Path(path)
    if not path.is_file():
        raise VCCError(f"{path}: {'not an image file' if path.exists() else 'no such image file'}")
    try:
        img = cv2.imread(str(path), cv2.IMREAD_COLOR)
    except cv2.error as e:  # e.g. a header claiming more pixels than OpenCV will allocate
        raise VCCError(f"{path}: an image OpenCV refuses ({str(e).strip().splitlines()[-1][:100]})") from None
    if img is None:
        raise VCCError(f"{path}: not an image OpenCV can read")
    if max(img.shape[:2]) > MAX_SIDE:
        raise VCCError(f"{path}: an image of {img.shape[1]}x{img.shape[0]} pixels; at most {MAX_SIDE} a side")
    return cv2.cvtColor(img, cv2.COLOR_BGR2RGB)


def read_scene(path: str | Path, cfg: VCCConfig = DEFAULT_CONFIG, image: bool | None = None) -> Scene:
    """A scene from a JSON scene file or a picture (`image`; by default decided by the
    file's extension), validated; errors name the file."""
    path = Path(path)
    if image is None:
        image = path.suffix.lower().lstrip(".") in IMAGE_EXTS
    try:
        if image:
            from vccjax.vision.perception import parse_image

            return parse_image(read_image(path)).validate(cfg)
        return Scene.load(path).validate(cfg)
    except VCCError as e:
        text = str(e)
        raise type(e)(text if text.startswith(str(path)) else f"{path}: {text}") from None
    except OSError as e:
        raise VCCError(f"{path}: cannot be read ({e.strerror or e})") from None


def unreachable(before: Scene, after: Scene) -> str | None:
    """Why no program can turn `before` into `after`, or None: the machine moves,
    recolours and removes objects and never makes one or changes a shape, so the
    output's shapes must be found among the input's, one for one."""
    left = [o.shape for o in before.objects]
    for o in after.objects:
        if o.shape not in left:
            where = f"({o.x:.2f}, {o.y:.2f})"
            if len(after.objects) > len(before.objects):
                return (f"the output has {len(after.objects)} objects and the input {len(before.objects)}: "
                        f"a program moves, recolours or removes objects, it never makes one (the {o.shape} at {where})")
            return f"the output's {o.shape} at {where} has no {o.shape} in the input to come from"
        left.remove(o.shape)
    return None


def _natural(key: str) -> tuple:
    return tuple(int(part) if part.isdigit() else part for part in re.split(r"(\d+)", key))


def pair_files(folder: str | Path) -> list[tuple[str, Path, Path]]:
    """(key, input file, output file) of every pair in `folder`, in natural key order."""
    folder = Path(folder)
    if not folder.is_dir():
        raise VCCError(f"{folder}: {'not a folder of example pairs' if folder.exists() else 'no such examples folder'}")
    sides: dict[str, dict[str, Path]] = {}
    for path in sorted(folder.iterdir()):
        if path.name.startswith("."):
            continue
        m = PAIR_FILE.match(path.name)
        if m is None or not path.is_file():
            raise VCCError(f"{path}: not half of a pair (name files <k>_in.json|png and <k>_out.json|png)")
        side = sides.setdefault(m["key"], {})
        if m["side"].lower() in side:
            raise VCCError(f"{path}: pair {m['key']!r} already has an {m['side'].lower()} file "
                           f"({side[m['side'].lower()].name})")
        side[m["side"].lower()] = path
    out = []
    for key in sorted(sides, key=_natural):
        missing = {"in", "out"} - set(sides[key])
        if missing:
            have = next(iter(sides[key].values()))
            raise VCCError(f"{have}: pair {key!r} has no {missing.pop()} file beside it")
        out.append((key, sides[key]["in"], sides[key]["out"]))
    if not out:
        raise VCCError(f"{folder}: holds no example pairs (<k>_in.json|png with <k>_out.json|png)")
    return out


def read_pairs(folder: str | Path, cfg: VCCConfig = DEFAULT_CONFIG,
               max_objects: int | None = None) -> list[tuple[str, Scene, Scene]]:
    """Every pair of `folder` as (key, input scene, output scene), each checked: an input
    holds an object (and at most `max_objects`), its output can be made from it, and no
    two pairs give one input two outputs (the machine is deterministic)."""
    from vccjax.machine.scene import scenes_match

    pairs, read = [], []
    for key, fin, fout in pair_files(folder):
        before, after = read_scene(fin, cfg), read_scene(fout, cfg)
        if not before.objects:
            raise SceneError(f"{fin}: no objects: a program acts on the input's objects, so an empty table "
                             f"shows it nothing to learn")
        if max_objects is not None and len(before.objects) > max_objects:
            raise SceneError(f"{fin}: {len(before.objects)} objects; the argument predictor reads at most "
                             f"{max_objects} (or learn with --args uniform)")
        why = unreachable(before, after)
        if why is not None:
            raise SceneError(f"{fout}: {why}")
        for fin0, fout0, before0, after0 in read:
            if scenes_match(before, before0, cfg.tau) and not scenes_match(after, after0, cfg.tau):
                raise SceneError(f"{fout}: its input is {fin0.name}'s, but its output is not {fout0.name}: "
                                 f"no program makes two outputs of one input")
        read.append((fin, fout, before, after))
        pairs.append((key, before, after))
    return pairs
