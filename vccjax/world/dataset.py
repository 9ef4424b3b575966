"""The examples of all concepts on disk: versioned, hashed NPZ files and a JSON manifest.

Layout of a dataset folder:
  manifest.json   format name and version, seed, machine config, per-concept file and
                  sha256, and the concepts that could not be built with the reason
  c000.npz ...    one file per concept (concept names hold characters unsafe in file
                  names): the concept, its program, seed, and the scene arrays.

Files are written byte-for-byte deterministically (fixed zip timestamps), so the same
seed gives the same bytes. Loading checks the format version, each file's sha256 and
each file's own content hash, and refuses foreign or corrupt files by name. Nothing is
unpickled.
"""

from __future__ import annotations

import hashlib
import io
import zipfile
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from vccjax import files
from vccjax.world.concepts import concept_names, reference_program
from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.errors import DataFileError, read_json
from vccjax.records import check_fields
from vccjax.world.pairs import TEST, TRAIN, TRAIN_WIDE, WIDE_PATIENCE, ExampleError, discriminate, make_pairs
from vccjax.machine.instructions import COLORS, SHAPES
from vccjax.world.rivals import rival_programs
from vccjax.machine.program import Program, parse
from vccjax.machine.scene import Scene, SceneObject

FORMAT = "vccjax-dataset"
VERSION = 8  # 2: examples must be well posed (pairs.Jitter); 3: small nudges too;
# 4: drawn shapes kept apart (scenes.drawn_cover), whole-scene and pointer nudges; 5: each object nudged alone;
# 6: training pairs tell the reference from its rivals (rivals.py); rivals left untold are listed per concept;
# 7: every loop of a program (not only the first) gets the straight-pass rivals;
# 8: rivals TRAIN's scenes leave untold get a second chance on the test's wider range (TRAIN_WIDE)
_FIELDS = 6  # alive, shape, color, x, y, width


# ---- scenes <-> arrays ----------------------------------------------------------------
def scenes_to_arrays(scenes: list[Scene], n_max: int) -> tuple[np.ndarray, np.ndarray]:
    objs = np.zeros((len(scenes), n_max, _FIELDS), np.float64)
    ptr = np.zeros((len(scenes), 3), np.float64)
    for i, sc in enumerate(scenes):
        for j, o in enumerate(sc.objects):
            objs[i, j] = 1, SHAPES.index(o.shape), COLORS.index(o.color), o.x, o.y, o.width
        if sc.pointer is not None:
            ptr[i] = 1, *sc.pointer
    return objs, ptr


def arrays_to_scenes(objs: np.ndarray, ptr: np.ndarray) -> list[Scene]:
    out = []
    for row, p in zip(objs, ptr):
        items = tuple(
            SceneObject(SHAPES[int(o[1])], COLORS[int(o[2])], float(o[3]), float(o[4]), float(o[5]))
            for o in row if o[0] == 1
        )
        out.append(Scene(items, (float(p[1]), float(p[2])) if p[0] == 1 else None))
    return out


def check_content(arrays: dict[str, np.ndarray], path: Path) -> None:
    """Refuse a concept file whose hash is right but whose scenes are not scenes (a file
    made by another program): every split's objects and pointers of the right shape,
    flags 0 or 1, shape and colour indices in range, and places on the unit square."""
    for split in ("train", "test"):
        for side in ("in", "out"):
            key = f"{split}_{side}"
            objs, ptr = arrays.get(key), arrays.get(f"{key}_pointer")
            if objs is None or ptr is None:
                raise DataFileError(f"{path}: lacks the arrays {key} and {key}_pointer")
            if objs.ndim != 3 or objs.shape[2] != _FIELDS or ptr.shape != (len(objs), 3):
                raise DataFileError(f"{path}: {key} has shape {objs.shape} (pointer {ptr.shape}), "
                                    f"expected (pairs, objects, {_FIELDS}) and (pairs, 3)")
            if not (np.isfinite(objs).all() and np.isfinite(ptr).all()):
                raise DataFileError(f"{path}: {key} holds values that are not finite")
            live = objs[objs[..., 0] == 1]
            if not np.isin(objs[..., 0], (0, 1)).all() or not np.isin(ptr[:, 0], (0, 1)).all():
                raise DataFileError(f"{path}: {key} has object or pointer flags other than 0 and 1")
            for col, names in ((1, SHAPES), (2, COLORS)):
                if not np.isin(live[:, col], np.arange(len(names))).all():
                    raise DataFileError(f"{path}: {key} has a {'shape' if col == 1 else 'colour'} index "
                                        f"outside 0..{len(names) - 1}")
            places = np.concatenate([live[:, 3:5].ravel(), ptr[ptr[:, 0] == 1][:, 1:].ravel()])
            if not ((places >= 0) & (places <= 1)).all() or not ((live[:, 5] > 0) & (live[:, 5] <= 1)).all():
                raise DataFileError(f"{path}: {key} places an object or pointer off the unit square")


# ---- deterministic NPZ with a content hash ----------------------------------------------
def _content_hash(arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for key in sorted(arrays):
        a = np.ascontiguousarray(arrays[key])
        h.update(key.encode() + b"\0" + a.dtype.str.encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()


def _text(s: str) -> np.ndarray:
    return np.frombuffer(s.encode(), np.uint8).copy()


def write_npz(path: Path, arrays: dict[str, np.ndarray]) -> str:
    """Write arrays plus `content_hash`; same arrays, same bytes. Returns the file's sha256."""
    arrays = dict(arrays)
    arrays["content_hash"] = _text(_content_hash(arrays))
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        for key in sorted(arrays):
            info = zipfile.ZipInfo(key + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            member = io.BytesIO()
            np.lib.format.write_array(member, np.ascontiguousarray(arrays[key]), allow_pickle=False)
            z.writestr(info, member.getvalue())
    data = buf.getvalue()
    files.write_whole(path, data)  # an interrupted build never leaves half a file
    return hashlib.sha256(data).hexdigest()


def read_npz(path: Path) -> dict[str, np.ndarray]:
    """Read a file written by write_npz, checking its content hash."""
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise DataFileError(f"{path}: missing") from None
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as e:
        raise DataFileError(f"{path}: not a readable NPZ file ({e})") from None
    stored = arrays.pop("content_hash", None)
    if stored is None:
        raise DataFileError(f"{path}: no content hash (not a vccjax file)")
    if bytes(stored).decode(errors="replace") != _content_hash(arrays):
        raise DataFileError(f"{path}: content hash mismatch (corrupt or edited)")
    return arrays


# ---- building ----------------------------------------------------------------------------
def stream_key(name: str) -> int:
    """The number a concept's random stream is seeded with, from its name: for one of the
    546, its place in the benchmark's list (so the shipped examples stay byte for byte
    what they were); for any other, the first 8 bytes of the name's sha256 (so a
    concept's examples do not depend on which others are built with it)."""
    names = concept_names()
    if name in names:
        return names.index(name)
    return int.from_bytes(hashlib.sha256(name.encode()).digest()[:8], "big") | (1 << 63)


def _concept_rng(seed: int, key: int, split: int) -> np.random.Generator:
    return np.random.default_rng([seed, key, split])


def file_name(name: str) -> str:
    """A concept's file in a dataset folder: c###.npz for the 546, u-<name>.npz otherwise."""
    names = concept_names()
    return f"c{names.index(name):03d}.npz" if name in names else f"u-{name}.npz"


def build_concept(name: str, program: Program, seed: int, cfg: VCCConfig) -> dict[str, np.ndarray]:
    arrays: dict[str, np.ndarray] = {
        "format_version": np.array([VERSION], np.int32),
        "concept": _text(name), "program": _text(program.text()),
        "seed": np.array([seed], np.int64), "raster": np.array([cfg.raster], np.int32),
    }
    key = stream_key(name)
    for split_id, (split, spec) in enumerate((("train", TRAIN), ("test", TEST))):
        rng = _concept_rng(seed, key, split_id)
        pairs = make_pairs(program, spec, rng, cfg)
        if split == "train":
            rivals = rival_programs(program)
            programs = [r for _, r in rivals]
            pairs, left = discriminate(program, pairs, programs, spec, rng, cfg)
            if left:  # a second chance on the test's wider scenes (pairs.TRAIN_WIDE)
                pairs, left = discriminate(program, pairs, programs, TRAIN_WIDE, rng, cfg, patience=WIDE_PATIENCE)
            arrays["train_rivals_left"] = _text("\n".join(rivals[i][0] for i in left))
        for side, scenes in (("in", [p[0] for p in pairs]), ("out", [p[1] for p in pairs])):
            objs, ptr = scenes_to_arrays(scenes, cfg.n_max)
            arrays[f"{split}_{side}"] = objs
            arrays[f"{split}_{side}_pointer"] = ptr
    return arrays


def _build_one(job: tuple[str, str, int, VCCConfig, str]) -> tuple[str, str, str | None, list[str]]:
    """(concept, sha256 of its file, error or None, rivals its training pairs leave untold)."""
    name, text, seed, cfg, out = job
    path = Path(out) / file_name(name)
    if path.exists():  # resume: keep a finished file if it is intact and from this seed and program
        try:
            a = read_npz(path)
            if (int(a["format_version"][0]) == VERSION and int(a["seed"][0]) == seed
                    and bytes(a["concept"]).decode() == name and bytes(a["program"]).decode() == text):
                return name, hashlib.sha256(path.read_bytes()).hexdigest(), None, _lines(a["train_rivals_left"])
        except (DataFileError, KeyError, IndexError, ValueError, OSError, zipfile.BadZipFile):
            pass  # damaged or foreign: built again
    try:
        arrays = build_concept(name, parse(text), seed, cfg)
    except ExampleError as e:
        return name, "", str(e), []
    return name, write_npz(path, arrays), None, _lines(arrays["train_rivals_left"])


def _lines(text: np.ndarray) -> list[str]:
    return [line for line in bytes(text).decode().split("\n") if line]


def build_dataset(
    out: str | Path, concepts: Iterable[str] | None = None, seed: int = 0,
    cfg: VCCConfig = DEFAULT_CONFIG, workers: int = 0, progress: bool = True,
    programs: dict[str, Program] | None = None,
) -> dict:
    """Build (or resume building) the dataset under `out`; returns the manifest. The
    concepts are the 546 (all, or those named), or, with `programs`, the concepts given
    there by name and program (their examples made from those programs). Every name is
    checked before anything is written."""
    from vccjax.parallel import map_with_progress

    out = Path(out)
    if programs is None:
        names = concept_names()
        wanted = names if concepts is None else list(concepts)
        unknown = [c for c in wanted if c not in names]
        if unknown:
            raise DataFileError(f"unknown concept(s): {', '.join(unknown[:5])}")
        texts = {n: reference_program(n).text() for n in wanted}
    else:
        if concepts is not None:
            missing = [c for c in concepts if c not in programs]
            if missing:
                raise DataFileError(f"not in the programs given: {', '.join(missing[:5])}")
        texts = {n: programs[n].text() for n in (programs if concepts is None else concepts)}
    files.check_writable(out, "dataset", folder=True)
    files.hold(out, "dataset folder")  # one builder at a time
    head = {"format": FORMAT, "version": VERSION, "seed": seed,
            "config": {"raster": cfg.raster, "n_max": cfg.n_max},
            "splits": {"train": vars_of(TRAIN), "train_wide": vars_of(TRAIN_WIDE), "test": vars_of(TEST)}}
    kept = _kept_entries(out, head, set(texts))
    jobs = [(n, text, seed, cfg, str(out)) for n, text in texts.items()]
    results = map_with_progress(_build_one, jobs, workers, 4, "concepts", progress, unit="concept")
    manifest = {
        **head,
        "concepts": {**kept["concepts"],
                     **{n: {"file": file_name(n), "sha256": h} for n, h, err, _ in results if not err}},
        "failed": {**kept["failed"], **{n: err for n, _, err, _ in results if err}},
        "rivals_left": {**kept["rivals_left"], **{n: left for n, _, err, left in results if left and not err}},
    }
    files.write_json(out / "manifest.json", manifest, sort_keys=True)
    return manifest


def _kept_entries(out: Path, head: dict, rebuilt: set[str]) -> dict:
    """What an existing manifest in `out` says of the concepts not built now: a build of
    some concepts into a dataset folder adds to it and never drops the others. A folder
    holding a dataset of another seed or world is refused rather than mixed."""
    path = out / "manifest.json"
    empty = {"concepts": {}, "failed": {}, "rivals_left": {}}
    if not path.exists():
        return empty
    old = Dataset(out).manifest
    if {k: old.get(k) for k in head} != head:
        raise DataFileError(f"{path}: this folder holds a dataset of another seed, world or format; "
                            "use another --out")
    kept = {k: {n: v for n, v in old.get(k, {}).items() if n not in rebuilt} for k in empty}
    for name, entry in kept["concepts"].items():  # a manifest written now vouches for every file it lists
        f = out / entry["file"]
        if not f.is_file() or hashlib.sha256(f.read_bytes()).hexdigest() != entry["sha256"]:
            raise DataFileError(f"{f}: {'missing' if not f.is_file() else 'sha256 differs from the manifest'}; "
                                f"build it again (--concepts {name}) before adding to this dataset")
    return kept


def rival_warnings(manifest: dict) -> list[str]:
    """One line per concept whose training pairs leave a rival of its program untold: for
    a user's own program, an instruction that changes no example is often a slip."""
    return [f"warning: {name}: no training pair tells its program from: {'; '.join(why)} "
            "(an instruction that changes no example is often a slip in the program)"
            for name, why in manifest["rivals_left"].items()]


def vars_of(spec) -> dict:
    return {"count": spec.count, "objects": list(spec.objects), "widths": list(spec.widths)}


# ---- loading -------------------------------------------------------------------------------
def shipped_folder() -> Path:
    """The seed-0 dataset of all 546 concepts, shipped in the package (about 6 MB): what
    `vcc dataset build` makes with the default seed, byte for byte (a test rebuilds a
    sample and compares hashes), so that induction needs no hour-long build first."""
    from importlib import resources

    return Path(str(resources.files("vccjax.world").joinpath("data/examples")))


def dataset_for(concepts: Iterable[str], seed: int, folder: str | Path | None, progress: bool = True) -> Dataset:
    """`folder` if given; else the shipped dataset for seed 0; else examples built (or
    resumed) for these concepts under ~/.cache/vccjax/examples-seed{seed}."""
    if folder is None and seed == 0 and (shipped_folder() / "manifest.json").exists():
        folder = shipped_folder()
    elif folder is None:
        folder = Path.home() / ".cache" / "vccjax" / f"examples-seed{seed}"
        build_dataset(folder, concepts, seed=seed, progress=progress)
    ds = Dataset(folder)
    missing = [c for c in concepts if c not in ds.manifest["concepts"]]
    if missing:
        more = " ..." if len(missing) > 5 else ""
        raise DataFileError(f"{folder}: no examples for {', '.join(missing[:5])}{more}")
    return ds


class Dataset:
    """A built dataset, verified on open; `pairs(concept, split)` gives Scene pairs."""

    def __init__(self, folder: str | Path):
        self.folder = Path(folder)
        path = self.folder / "manifest.json"
        manifest = read_json(path, DataFileError, "missing (build with `vcc dataset build`)")
        if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
            raise DataFileError(f"{path}: not a {FORMAT} manifest")
        if manifest.get("version") != VERSION:
            raise DataFileError(f"{path}: format version {manifest.get('version')}, this vccjax reads {VERSION}")
        concepts = manifest.get("concepts")
        if not isinstance(concepts, dict) or not (concepts or manifest.get("failed")):
            raise DataFileError(f"{path}: 'concepts' must be a non-empty object of concept entries")
        for name, entry in concepts.items():
            check_fields(entry, {"file": (str,), "sha256": (str,)}, f"{path}: concept {name}")
            if Path(entry["file"]).name != entry["file"]:
                raise DataFileError(f"{path}: concept {name}: its file must lie in the dataset folder")
        for key in ("failed", "rivals_left"):
            if not isinstance(manifest.get(key, {}), dict):
                raise DataFileError(f"{path}: '{key}' must be an object")
        self.manifest = manifest
        self._cache: dict[str, dict[str, np.ndarray]] = {}

    @property
    def concepts(self) -> list[str]:
        return list(self.manifest["concepts"])

    def arrays(self, concept: str) -> dict[str, np.ndarray]:
        if concept not in self._cache:
            entry = self.manifest["concepts"].get(concept)
            if entry is None:
                raise DataFileError(f"{self.folder}: concept {concept!r} is not in this dataset")
            path = self.folder / entry["file"]
            if not path.exists():
                raise DataFileError(f"{path}: missing")
            if hashlib.sha256(path.read_bytes()).hexdigest() != entry["sha256"]:
                raise DataFileError(f"{path}: sha256 differs from the manifest (corrupt or replaced)")
            arrays = read_npz(path)
            lacking = sorted({"format_version", "seed", "concept", "program"} - set(arrays))
            if lacking:
                raise DataFileError(f"{path}: lacks the arrays {', '.join(lacking)} (not a concept file)")
            if int(arrays["format_version"][0]) != VERSION:
                raise DataFileError(f"{path}: format version {int(arrays['format_version'][0])}")
            if bytes(arrays["concept"]).decode() != concept:
                raise DataFileError(f"{path}: holds concept {bytes(arrays['concept']).decode()!r}, not {concept!r}")
            check_content(arrays, path)
            self._cache[concept] = arrays
        return self._cache[concept]

    def program(self, concept: str) -> Program:
        """The program the concept's examples were made with (its answer: read only by
        research settings that ask for it, `--args oracle` and fixation guidance)."""
        arrays = self.arrays(concept)
        if "program" not in arrays or not bytes(arrays["program"]).decode().strip():
            raise DataFileError(f"{self.folder}: {concept!r} has no program stored with its examples "
                                "(--args oracle and fixation guidance read it)")
        return parse(bytes(arrays["program"]).decode())

    def sha256(self, concept: str) -> str:
        """The manifest's hash of the concept's file: what identifies its examples."""
        entry = self.manifest["concepts"].get(concept)
        if entry is None:
            raise DataFileError(f"{self.folder}: concept {concept!r} is not in this dataset")
        return entry["sha256"]

    def rivals_left(self, concept: str) -> list[str]:
        """The rivals of the reference (rivals.py) that no training pair tells apart."""
        return _lines(self.arrays(concept)["train_rivals_left"])

    def pairs(self, concept: str, split: str = "train") -> list[tuple[Scene, Scene]]:
        if split not in ("train", "test"):
            raise ValueError(f"split must be 'train' or 'test', got {split!r}")
        a = self.arrays(concept)
        ins = arrays_to_scenes(a[f"{split}_in"], a[f"{split}_in_pointer"])
        outs = arrays_to_scenes(a[f"{split}_out"], a[f"{split}_out_pointer"])
        return list(zip(ins, outs))
