"""Hostile input over every `vcc` command, each case run through the real CLI as a
subprocess (the table is `tests/vcc/hostile_cases.py`).

Every case must end (1) with a non-zero exit code, (2) without a traceback (nor the
CLI's "internal error" line, a crash whose traceback went to a file), (3) with exactly
one non-empty line on stderr, (4) within TIMEOUT seconds, and (5) without a half-written
file: each path in the case's "writes" is afterwards absent or byte-for-byte what it was
before (a folder: the same entries, each the same), and no temporary file (`*.tmp*`,
`.*.tmp`) is left anywhere in its folder.

A case runs in its own temporary folder (the cwd), with HOME and VCC_LIBRARY inside it,
VCCJAX_CACHE=off, JAX_PLATFORMS=cpu, stdin closed, in its own session (a timeout kills
the whole group) and under an address-space limit (a case that asks for absurd sizes
fails instead of taking the machine's memory). Set VCC_HOSTILE_LOG=FILE to get one JSON
line per case (argv, exit code, seconds, stderr's first and last line, problems).
"""

from __future__ import annotations

import fnmatch
import hashlib
import json
import os
import random
import re
import resource
import shutil
import signal
import struct
import subprocess
import sys
import time
import zlib
from pathlib import Path

import pytest

from tests.vcc.hostile_cases import CASES

REPO = Path(__file__).resolve().parents[2]
TIMEOUT = 60.0
MEMORY_LIMIT = 8 * 2**30  # bytes of address space per case
SHIPPED_DATASET = REPO / "vccjax" / "world" / "data" / "examples"
SHIPPED_LIBRARY = REPO / "search" / "data" / "library.json"
SHIPPED_WEIGHTS = REPO / "argpred" / "weights" / "argpred.msgpack"
DATASET_CONCEPT = "remove_top_obj"  # the concept the small dataset fixtures hold
LONG_NUMBER = "1" + "0" * 400  # a 401-digit integer: a finite JSON number no float can hold


# ---- templates --------------------------------------------------------------------------
def templates(tmp: Path) -> dict[str, str]:
    return {
        "tmp": str(tmp),
        "file": str(tmp / "plain.txt"),  # an existing regular file
        "dir": str(tmp / "adir"),  # an existing (empty) directory
        "empty": str(tmp / "empty.txt"),  # an empty file
        "bin": str(tmp / "binary.bin"),  # random bytes, NULs included
        "missing": str(tmp / "no" / "such" / "path"),
        "ro": "/proc/vcc-hostile/out",  # cannot be created
        "ro_dir": "/proc/vcc-hostile",
        "full": "/dev/full",  # every write fails with ENOSPC
        "shipped": str(SHIPPED_DATASET),
        "repo": str(REPO),
    }


_TEMPLATE = re.compile(r"\{([a-z_]+)\}")


def expand(text: str, names: dict[str, str]) -> str:
    """Replace the known {name} templates; any other brace is left as it is."""
    return _TEMPLATE.sub(lambda m: names.get(m.group(1), m.group(0)), text)


# ---- fixture helpers ----------------------------------------------------------------------
def _write(path: Path, data: str | bytes) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(data, bytes):
        path.write_bytes(data)
    else:
        path.write_text(data)
    return path


def _json(path: Path, content) -> Path:
    return _write(path, json.dumps(content))


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _png(width: int, height: int, rows: bytes | None = None, idat: bytes | None = None) -> bytes:
    """An 8-bit RGB PNG; `rows` is the raw pixel data (3 bytes a pixel, row by row)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    if idat is None:
        assert rows is not None and len(rows) == width * height * 3
        raw = b"".join(b"\x00" + rows[y * width * 3:(y + 1) * width * 3] for y in range(height))
        idat = zlib.compress(raw)
    head = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", idat) + chunk(b"IEND", b"")


def _one_colour(size: int, rgb: tuple[int, int, int]) -> bytes:
    return _png(size, size, bytes(rgb) * size * size)


def _scene(*objects, pointer=None) -> dict:
    d = {"objects": [dict(zip(("shape", "color", "x", "y", "width"), o)) for o in objects]}
    if pointer is not None:
        d["pointer"] = pointer
    return d


OK_SCENE = _scene(("square", "red", 0.3, 0.3, 0.1), ("circle", "blue", 0.7, 0.7, 0.1), pointer=[0.5, 0.5])


def base(tmp: Path) -> None:
    """What every case's folder holds."""
    _write(tmp / "plain.txt", "hello\n")
    (tmp / "adir").mkdir()
    _write(tmp / "empty.txt", b"")
    _write(tmp / "binary.bin", bytes(random.Random(1).randrange(256) for _ in range(4096)) + b"\0\xff\xfe")
    (tmp / "home").mkdir()
    for suffix in ("png", "gif", "json", "mp4", "jpg", "msgpack"):
        (tmp / f"dir.{suffix}").mkdir()  # a folder where a file is meant


# ---- named setups -------------------------------------------------------------------------
def setup_scenes(tmp: Path) -> None:
    s = tmp / "s"
    _json(s / "ok.json", OK_SCENE)
    obj = {"shape": "square", "color": "red", "x": 0.5, "y": 0.5, "width": 0.1}

    def with_obj(**fields):
        return {"objects": [{**obj, **fields}]}

    raw = {
        "huge_x.json": '{"objects": [{"shape": "square", "color": "red", "x": %s, "y": 0.5, "width": 0.1}]}'
                       % LONG_NUMBER,
        "huge_width.json": '{"objects": [{"shape": "square", "color": "red", "x": 0.5, "y": 0.5, "width": %s}]}'
                           % LONG_NUMBER,
        "huge_pointer.json": '{"objects": [], "pointer": [%s, 0.5]}' % LONG_NUMBER,
        "digits5000.json": '{"objects": [], "pointer": [%s, 0.5]}' % ("9" * 5000),
        "x_nan.json": '{"objects": [{"shape": "square", "color": "red", "x": NaN, "y": 0.5, "width": 0.1}]}',
        "x_inf.json": '{"objects": [{"shape": "square", "color": "red", "x": Infinity, "y": 0.5, "width": 0.1}]}',
        "x_1e400.json": '{"objects": [{"shape": "square", "color": "red", "x": 1e400, "y": 0.5, "width": 0.1}]}',
        "pointer_nan.json": '{"objects": [], "pointer": [NaN, 0.5]}',
        "nested.json": "[" * 100_000 + "]" * 100_000,
        "nested_objects.json": '{"objects": ' + "[" * 100_000 + "]" * 100_000 + "}",
        "nested_pointer.json": '{"objects": [], "pointer": ' + "[" * 100_000 + "]" * 100_000 + "}",
        "trailing.json": json.dumps(OK_SCENE) + " garbage",
        "truncated.json": json.dumps(OK_SCENE)[:25],
        "not_json.json": "{objects: square}",
        "dup_key.json": '{"objects": [], "objects": 5}',
    }
    for name, text in raw.items():
        _write(s / name, text)
    content = {
        "pointer_nested.json": {"objects": [], "pointer": [[1], [2]]},
        "pointer_strings.json": {"objects": [], "pointer": ["left", "top"]},
        "pointer_nulls.json": {"objects": [], "pointer": [None, None]},
        "pointer_short.json": {"objects": [], "pointer": [0.5]},
        "pointer_long.json": {"objects": [], "pointer": [0.5, 0.5, 0.5]},
        "pointer_dict.json": {"objects": [], "pointer": {"x": 0.5, "y": 0.5}},
        "pointer_string.json": {"objects": [], "pointer": "0.5,0.5"},
        "pointer_outside.json": {"objects": [], "pointer": [5, -5]},
        "list.json": [1, 2, 3],
        "string.json": "scene",
        "null.json": None,
        "number.json": 42,
        "no_objects_key.json": {"things": []},
        "objects_dict.json": {"objects": {}},
        "objects_string.json": {"objects": "square"},
        "objects_ints.json": {"objects": [1, 2]},
        "objects_lists.json": {"objects": [["square", "red", 0.5, 0.5, 0.1]]},
        "obj_missing.json": {"objects": [{"shape": "square"}]},
        "x_string.json": with_obj(x="0.5"),
        "x_null.json": with_obj(x=None),
        "x_list.json": with_obj(x=[0.5]),
        "x_dict.json": with_obj(x={"v": 0.5}),
        "x_outside.json": with_obj(x=3.0),
        "shape_int.json": with_obj(shape=7),
        "shape_list.json": with_obj(shape=["square"]),
        "shape_dict.json": with_obj(shape={"square": 1}),
        "shape_unknown.json": with_obj(shape="hexagon"),
        "color_unknown.json": with_obj(color="purple"),
        "color_null.json": with_obj(color=None),
        "width_zero.json": with_obj(width=0),
        "width_negative.json": with_obj(width=-0.1),
        "width_huge.json": with_obj(width=1e308),
        "eleven.json": {"objects": [{**obj, "x": 0.05 + 0.09 * i, "width": 0.05} for i in range(11)]},
        "ten_thousand.json": {"objects": [obj] * 10_000},
        "overlap.json": {"objects": [obj, {**obj, "x": 0.52}]},
    }
    for name, c in content.items():
        _json(s / name, c)
    _write(s / "bom.json", b"\xef\xbb\xbf" + json.dumps(OK_SCENE).encode())
    _write(s / "utf16.json", json.dumps(OK_SCENE).encode("utf-16"))
    _write(s / "latin1.json", b'{"objects": [], "name": "\xff\xfe\xe9"}')
    _write(s / "binary.json", bytes(random.Random(2).randrange(256) for _ in range(2048)))
    _write(s / "empty.json", b"")
    (s / "dir.json").mkdir()
    (s / "loop.json").symlink_to(s / "loop.json")  # a symlink to itself


def setup_images(tmp: Path) -> None:
    i = tmp / "img"
    _write(i / "white.png", _one_colour(128, (255, 255, 255)))
    _write(i / "black.png", _one_colour(128, (0, 0, 0)))
    _write(i / "grey.png", _one_colour(128, (128, 128, 128)))
    _write(i / "red.png", _one_colour(128, (255, 0, 0)))  # all one colour: one object as large as the image
    rng = random.Random(3)
    _write(i / "noise.png", _png(128, 128, bytes(rng.randrange(256) for _ in range(128 * 128 * 3))))
    _write(i / "tiny.png", _one_colour(1, (255, 255, 255)))
    _write(i / "empty.png", b"")
    _write(i / "garbage.png", bytes(rng.randrange(256) for _ in range(5000)))
    _write(i / "text.png", json.dumps(OK_SCENE))
    _write(i / "truncated.png", _one_colour(128, (255, 255, 255))[:60])
    _write(i / "bomb.png", _png(40_000, 40_000, idat=zlib.compress(b"\x00" * 1000)))  # 1.6 gigapixels claimed
    _write(i / "white.jpg", _one_colour(64, (255, 255, 255)))  # a PNG under a .jpg name: still no objects
    (i / "dir.png").mkdir()


def setup_progs(tmp: Path) -> None:
    p = tmp / "p"
    _write(p / "binary.vcc", bytes(random.Random(4).randrange(256) for _ in range(1024)) + b"\xff\xfe")
    _write(p / "empty.vcc", "")
    _write(p / "comments.vcc", "# nothing but a comment\n# and another\n")
    _write(p / "bad.vcc", "scene_parse\njump\n")
    _write(p / "unclosed.vcc", "scene_parse\nfill_color(red\n")
    _write(p / "huge.vcc", "scene_parse\n" + "fill_color(red)\n" * 200_000 + "jump\n")  # a bad last line
    _write(p / "nul.vcc", "scene_parse\x00; fill_color(red)\n")
    (p / "dir.vcc").mkdir()
    # `name: program` lines (dataset build --programs, bench learn --programs)
    _write(p / "list_ok.txt", "my_recolor: scene_parse; set_shape_attn(square); top_down_attend; fill_color(blue)\n")
    _write(p / "list_badline.txt", "my_recolor scene_parse; fill_color(blue)\n")
    _write(p / "list_shipped.txt", "remove_top_obj: scene_parse; fixate(top); top_down_attend\n")
    _write(p / "list_dup.txt", "my_a: scene_parse; fill_color(red)\nmy_a: scene_parse; fill_color(blue)\n")
    _write(p / "list_badprog.txt", "my_a: scene_parse; jump(3)\n")
    _write(p / "list_empty.txt", "# no concept here\n\n")
    _write(p / "list_upper.txt", "MyConcept: scene_parse; fill_color(red)\n")
    _write(p / "list_noprog.txt", "my_a:\n")
    _write(p / "list_binary.txt", bytes(random.Random(5).randrange(256) for _ in range(1024)) + b"\xff\xfe")
    _write(p / "list_long_name.txt", "a" * 65 + ": scene_parse; fill_color(red)\n")


def setup_fifo(tmp: Path) -> None:
    for name in ("fifo.json", "fifo.txt", "fifo.vcc", "fifo.png"):
        os.mkfifo(tmp / name)  # a read blocks forever: nobody writes


def _small_dataset(folder: Path) -> tuple[dict, str]:
    """A one-concept copy of the shipped dataset: (manifest, its npz file name)."""
    manifest = json.loads((SHIPPED_DATASET / "manifest.json").read_text())
    entry = manifest["concepts"][DATASET_CONCEPT]
    manifest["concepts"] = {DATASET_CONCEPT: entry}
    manifest["rivals_left"] = {k: v for k, v in manifest.get("rivals_left", {}).items() if k == DATASET_CONCEPT}
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(SHIPPED_DATASET / entry["file"], folder / entry["file"])
    _json(folder / "manifest.json", manifest)
    return manifest, entry["file"]


def _set_file(folder: Path, manifest: dict, name: str, data: bytes) -> None:
    """Replace the concept's npz by `data`, its sha256 put in the manifest (so only the
    content is wrong)."""
    _write(folder / name, data)
    manifest["concepts"][DATASET_CONCEPT]["sha256"] = hashlib.sha256(data).hexdigest()
    _json(folder / "manifest.json", manifest)


def _npz_bytes(arrays: dict) -> bytes:
    from vccjax.world.dataset import write_npz  # the real writer: a valid content hash

    tmp = Path(os.environ.get("TMPDIR", "/tmp")) / f"hostile-{os.getpid()}-{time.time_ns()}.npz"
    try:
        write_npz(tmp, arrays)
        return tmp.read_bytes()
    finally:
        tmp.unlink(missing_ok=True)


def setup_ds(tmp: Path) -> None:
    import numpy as np

    d = tmp / "ds"
    _small_dataset(d / "ok")
    m, f = _small_dataset(d / "flipped")  # one byte changed: sha256 mismatch
    data = bytearray((d / "flipped" / f).read_bytes())
    data[len(data) // 2] ^= 0xFF
    _write(d / "flipped" / f, bytes(data))
    m, f = _small_dataset(d / "garbage_npz")
    _set_file(d / "garbage_npz", m, f, bytes(random.Random(6).randrange(256) for _ in range(4000)))
    m, f = _small_dataset(d / "empty_npz")
    _set_file(d / "empty_npz", m, f, b"")
    m, f = _small_dataset(d / "truncated_npz")
    _set_file(d / "truncated_npz", m, f, (SHIPPED_DATASET / f).read_bytes()[:3000])
    with np.load(SHIPPED_DATASET / f, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files if k != "content_hash"}
    m, f = _small_dataset(d / "nan_coords")
    bad = dict(arrays)
    bad["train_in"] = arrays["train_in"].copy()
    bad["train_in"][..., 3] = np.where(arrays["train_in"][..., 0] == 1, np.nan, arrays["train_in"][..., 3])
    _set_file(d / "nan_coords", m, f, _npz_bytes(bad))
    m, f = _small_dataset(d / "shape_index")
    bad = dict(arrays)
    bad["train_in"] = arrays["train_in"].copy()
    bad["train_in"][..., 1] = np.where(arrays["train_in"][..., 0] == 1, 99, arrays["train_in"][..., 1])
    _set_file(d / "shape_index", m, f, _npz_bytes(bad))
    m, f = _small_dataset(d / "short_rows")
    bad = dict(arrays)
    bad["train_in"] = arrays["train_in"][..., :3].copy()
    _set_file(d / "short_rows", m, f, _npz_bytes(bad))
    m, f = _small_dataset(d / "missing_keys")
    _set_file(d / "missing_keys", m, f, _npz_bytes({"format_version": arrays["format_version"]}))
    m, f = _small_dataset(d / "no_program")
    bad = {k: v for k, v in arrays.items() if k != "program"}
    _set_file(d / "no_program", m, f, _npz_bytes(bad))
    m, f = _small_dataset(d / "bad_program")
    bad = dict(arrays)
    bad["program"] = np.frombuffer(b"scene_parse; jump(3)", np.uint8).copy()
    _set_file(d / "bad_program", m, f, _npz_bytes(bad))
    m, f = _small_dataset(d / "npz_is_dir")
    (d / "npz_is_dir" / f).unlink()
    (d / "npz_is_dir" / f).mkdir()
    m, f = _small_dataset(d / "npz_missing")
    (d / "npz_missing" / f).unlink()
    m, f = _small_dataset(d / "traversal")
    m["concepts"][DATASET_CONCEPT]["file"] = "../../../../../../etc/passwd"
    _json(d / "traversal" / "manifest.json", m)
    m, f = _small_dataset(d / "entry_no_file")
    m["concepts"][DATASET_CONCEPT] = {}
    _json(d / "entry_no_file" / "manifest.json", m)
    m, f = _small_dataset(d / "entry_string")
    m["concepts"][DATASET_CONCEPT] = "c000.npz"
    _json(d / "entry_string" / "manifest.json", m)
    m, f = _small_dataset(d / "concepts_list")
    m["concepts"] = []
    _json(d / "concepts_list" / "manifest.json", m)
    m, f = _small_dataset(d / "concepts_none")
    m["concepts"] = {}
    _json(d / "concepts_none" / "manifest.json", m)
    m, f = _small_dataset(d / "no_failed_key")
    del m["failed"]
    _json(d / "no_failed_key" / "manifest.json", m)
    m, f = _small_dataset(d / "manifest_list")
    _json(d / "manifest_list" / "manifest.json", [])
    m, f = _small_dataset(d / "foreign")
    _json(d / "foreign" / "manifest.json", {"format": "something-else", "version": 1})
    m, f = _small_dataset(d / "version")
    m["version"] = 999
    _json(d / "version" / "manifest.json", m)
    m, f = _small_dataset(d / "manifest_binary")
    _write(d / "manifest_binary" / "manifest.json", bytes(random.Random(7).randrange(256) for _ in range(512)))
    m, f = _small_dataset(d / "manifest_nested")
    _write(d / "manifest_nested" / "manifest.json", "[" * 100_000 + "]" * 100_000)
    m, f = _small_dataset(d / "manifest_dir")
    (d / "manifest_dir" / "manifest.json").unlink()
    (d / "manifest_dir" / "manifest.json").mkdir()
    (d / "no_manifest").mkdir(parents=True)


def _record(concept="remove_top_obj", found=True, iteration=0,
            program="scene_parse; fixate(top); top_down_attend; remove_from_imagine_buffer", **more) -> dict:
    r = {"concept": concept, "found": found, "iteration": iteration, "program": program if found else None,
         "compressed": program if found else None, "dl": 12.5 if found else None, "rank": 10 if found else None,
         "nodes": 5, "programs_run": 5, "covered": 10, "seconds": 0.5, "compile_seconds": 0.1,
         "test_correct": 50 if found else None, "test_total": 50 if found else None, "subroutines": 0,
         "session": 0, "at": 1700000000.0}
    r.update(more)
    return r


INDUCE_SETTINGS = {"budget": 1, "order": 1, "args": "uniform", "subroutines": True, "epsilon": 0.1,
                   "max_iterations": 1, "max_subroutines": 100, "delta": 0.01}  # what the cheap induce cases use


def _run_folder(folder: Path, lines: list[str] | None = None, meta=None, model=None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    if meta is not False:
        _json(folder / "run.json", meta if meta is not None else
              {"format": "vccjax-induce", "version": 1, "settings": INDUCE_SETTINGS, "sessions": [1700000000.0],
               "start_model": "uniform"})
    if lines is None:
        lines = [json.dumps(_record()), json.dumps(_record("remove_left_most_obj", found=False))]
    _write(folder / "results.jsonl", "".join(line + "\n" for line in lines))
    tokens = 28
    if model is not False:
        _json(folder / "model-0.json", model if model is not None else
              {"iteration": 0, "order": 1, "subroutines": [], "logp": [[-3.3322] * tokens] * tokens})
    return folder


def setup_runs(tmp: Path) -> None:
    r = tmp / "runs"
    # a good record of another concept after each bad line: the bad line is not superseded
    good = json.dumps(_record("remove_bottom_obj",
                              program="scene_parse; fixate(bottom); top_down_attend; remove_from_imagine_buffer"))
    _run_folder(r / "ok")
    _run_folder(r / "line_list", ["[1, 2, 3]", good])
    _run_folder(r / "line_found_str", [json.dumps(_record(found="no")), good])
    _run_folder(r / "line_iter_str", [json.dumps(_record(iteration="0")), good])
    _run_folder(r / "line_not_json", ["{not json", good])
    _run_folder(r / "line_null", ["null", good])
    _run_folder(r / "line_program_null", [json.dumps({**_record(), "program": None}), good])
    _run_folder(r / "line_program_int", [json.dumps({**_record(), "program": 5}), good])
    _run_folder(r / "line_program_bad", [json.dumps(_record(program="scene_parse; jump")), good])
    _run_folder(r / "line_concept_int", [json.dumps({**_record(), "concept": 7}), good])
    _run_folder(r / "line_nested", ["[" * 100_000 + "]" * 100_000, good])
    _run_folder(r / "line_huge_dl", [json.dumps(_record())[:-1] + ', "dl": ' + LONG_NUMBER + "}", good])
    _run_folder(r / "only_unfound", [json.dumps(_record(found=False))])
    _run_folder(r / "results_binary", [])
    _write(r / "results_binary" / "results.jsonl", bytes(random.Random(8).randrange(256) for _ in range(2048)))
    _run_folder(r / "results_dir", [])
    (r / "results_dir" / "results.jsonl").unlink()
    (r / "results_dir" / "results.jsonl").mkdir()
    _run_folder(r / "no_results", [])
    (r / "no_results" / "results.jsonl").unlink()
    _run_folder(r / "meta_list", meta=[])
    _run_folder(r / "meta_garbage", meta=None)
    _write(r / "meta_garbage" / "run.json", "{not json")
    _run_folder(r / "meta_missing", meta=False)
    _run_folder(r / "meta_no_settings", meta={"format": "vccjax-induce", "version": 1})
    _run_folder(r / "meta_settings_list", meta={"format": "vccjax-induce", "version": 1, "settings": [],
                                                "sessions": []})
    _run_folder(r / "meta_sessions_str", meta={"format": "vccjax-induce", "version": 1,
                                               "settings": INDUCE_SETTINGS, "sessions": "yesterday"})
    _run_folder(r / "meta_order_str", meta={"format": "vccjax-induce", "version": 1, "sessions": [],
                                            "settings": {**INDUCE_SETTINGS, "order": "one"}})
    _run_folder(r / "meta_budget_none", meta={"format": "vccjax-induce", "version": 1, "sessions": [],
                                              "settings": {k: v for k, v in INDUCE_SETTINGS.items() if k != "budget"}})
    (r / "meta_dir").mkdir()
    (r / "meta_dir" / "run.json").mkdir()
    _write(r / "meta_dir" / "results.jsonl", good + "\n")
    # model-K.json variants (induce --model)
    m = r / "models"
    n = 28
    _json(m / "wrong_shape.json", {"iteration": 0, "order": 1, "subroutines": [], "logp": [[-1.0] * 3] * 3})
    _write(m / "nan.json", json.dumps({"iteration": 0, "order": 1, "subroutines": [],
                                       "logp": [[-3.3] * n] * n}).replace("-3.3", "NaN", 1))
    _json(m / "subroutines_str.json", {"iteration": 0, "order": 1, "subroutines": "none", "logp": [[-3.3] * n] * n})
    _json(m / "subroutines_bad.json", {"iteration": 0, "order": 1, "subroutines": [["jump", "dance"]],
                                       "logp": [[-3.3] * 29] * 29})
    _json(m / "order_0.json", {"iteration": 0, "order": 0, "subroutines": [], "logp": [[-3.3] * n] * n})
    _json(m / "order_str.json", {"iteration": 0, "order": "first", "subroutines": [], "logp": [[-3.3] * n] * n})
    _json(m / "logp_ragged.json", {"iteration": 0, "order": 1, "subroutines": [], "logp": [[-3.3] * n, [1]]})
    _json(m / "logp_strings.json", {"iteration": 0, "order": 1, "subroutines": [], "logp": [["x"] * n] * n})
    _write(m / "logp_huge.json", json.dumps({"iteration": 0, "order": 1, "subroutines": [],
                                             "logp": [[-3.3] * n] * n}).replace("-3.3", LONG_NUMBER, 1))
    _json(m / "list.json", [])
    _json(m / "empty_object.json", {})
    _write(m / "garbage.json", "{{{{")
    _write(m / "nested.json", "[" * 100_000 + "]" * 100_000)


def _seal(content: dict) -> dict:
    from vccjax.sealed import seal

    return seal({k: v for k, v in content.items() if k != "content_sha256"})


def setup_libs(tmp: Path) -> None:
    lib = tmp / "lib"
    shipped = json.loads(SHIPPED_LIBRARY.read_text())
    _write(lib / "garbage.json", "not a library")
    _json(lib / "list.json", [])
    _json(lib / "foreign.json", {"format": "something-else"})
    _json(lib / "version.json", _seal({**shipped, "version": 999}))
    _json(lib / "edited.json", {**shipped, "epsilon": 0.2})  # sha256 no longer matches
    _json(lib / "neg_counts.json", _seal({**shipped, "transitions": [[0, 1, -1_000_000_000]]}))
    _json(lib / "big_index.json", _seal({**shipped, "transitions": [[10**9, 0, 1]]}))
    _json(lib / "float_index.json", _seal({**shipped, "transitions": [[0.5, 1.5, 1]]}))
    _json(lib / "transitions_str.json", _seal({**shipped, "transitions": "many"}))
    _json(lib / "order_7.json", _seal({**shipped, "order": 7}))
    _json(lib / "epsilon_neg.json", _seal({**shipped, "epsilon": -1.0}))
    _write(lib / "epsilon_nan.json", json.dumps(_seal({**shipped, "epsilon": float("nan")})))
    _json(lib / "subs_unknown.json", _seal({**shipped, "subroutines": [["jump", "dance"]]}))
    _json(lib / "subs_empty.json", _seal({**shipped, "subroutines": [[]]}))
    _json(lib / "subs_str.json", _seal({**shipped, "subroutines": "x"}))
    _json(lib / "card_list.json", _seal({**shipped, "card": []}))
    card = dict(shipped["card"])
    _json(lib / "card_settings_list.json", _seal({**shipped, "card": {**card, "settings": []}}))
    _json(lib / "card_no_run.json", _seal({**shipped, "card": {k: v for k, v in card.items() if k != "source_run"}}))
    _json(lib / "card_budget_str.json", _seal({**shipped, "card": {**card, "settings": {**card["settings"],
                                                                                          "budget": "lots"}}}))
    _write(lib / "nested.json", "[" * 100_000 + "]" * 100_000)
    _write(lib / "binary.json", bytes(random.Random(9).randrange(256) for _ in range(2048)))
    (lib / "dir.json").mkdir()


def _card() -> dict:
    return json.loads(SHIPPED_WEIGHTS.with_suffix(".json").read_text())


def _weights(folder: Path, name: str, data: bytes | None = None, card: dict | None = None,
             card_text: str | None = None, card_sha: bool = True) -> None:
    data = SHIPPED_WEIGHTS.read_bytes() if data is None else data
    _write(folder / f"{name}.msgpack", data)
    card = _card() if card is None else card
    if card_sha and isinstance(card, dict):
        card = {**card, "sha256": hashlib.sha256(data).hexdigest()}
    _write(folder / f"{name}.json", card_text if card_text is not None else json.dumps(card))


def setup_weights(tmp: Path) -> None:
    w = tmp / "w"
    card = _card()
    rng = random.Random(10)
    _weights(w, "garbage", bytes(rng.randrange(256) for _ in range(4096)))
    _weights(w, "empty", b"")
    _weights(w, "truncated", SHIPPED_WEIGHTS.read_bytes()[:1000])
    _weights(w, "msgpack_int", b"\x2a")  # the msgpack of the number 42
    _weights(w, "msgpack_list", b"\x93\x01\x02\x03")  # [1, 2, 3]
    _weights(w, "flipped", card=card, card_sha=False,
             data=bytes(b ^ 0xFF if k == 500 else b for k, b in enumerate(SHIPPED_WEIGHTS.read_bytes())))
    _weights(w, "huge_hidden", card={**card, "model": {**card["model"], "hidden": 1_000_000_000}})
    _weights(w, "negative_hidden", card={**card, "model": {**card["model"], "hidden": -5}})
    _weights(w, "zero_kernel", card={**card, "model": {**card["model"], "kernel": 0}})
    _weights(w, "huge_kernel", card={**card, "model": {**card["model"], "kernel": 100_000}})
    _weights(w, "members_str", card={**card, "model": {**card["model"], "members": "three"}})
    _weights(w, "members_zero", card={**card, "model": {**card["model"], "members": 0}})
    _weights(w, "evidence_bad", card={**card, "model": {**card["model"], "evidence": "vibes"}})
    _weights(w, "model_list", card={**card, "model": []})
    _weights(w, "labels_other", card={**card, "labels": [["fill_color", "purple"]]})
    _weights(w, "card_list", card=[], card_text="[]")
    _weights(w, "card_garbage", card_text="{not json")
    _weights(w, "card_binary", card_text=None, card={**card})
    _write(w / "card_binary.json", bytes(rng.randrange(256) for _ in range(1024)) + b"\xff\xfe")
    _weights(w, "card_nested", card_text="[" * 100_000 + "]" * 100_000)
    _write(w / "no_card.msgpack", SHIPPED_WEIGHTS.read_bytes())
    (w / "dir.msgpack").mkdir()
    _write(w / "dir.json", json.dumps(card))


def setup_saved(tmp: Path) -> None:
    """The user's library of saved concepts ($VCC_LIBRARY is {tmp}/library)."""
    from vccjax.sealed import seal

    lib = tmp / "library"
    record = {"format": "vccjax-concept", "version": 1, "program": "scene_parse; top_down_attend; fill_color(blue)",
              "pairs": 1}
    _write(lib / "notjson.json", "{not json")
    _json(lib / "edited.json", {**seal({**record, "name": "edited"}), "program": "scene_parse"})
    _json(lib / "badprog.json", seal({**record, "name": "badprog", "program": "scene_parse; jump"}))
    _json(lib / "intprog.json", seal({**record, "name": "intprog", "program": 5}))
    _json(lib / "noprog.json", seal({k: v for k, v in {**record, "name": "noprog"}.items() if k != "program"}))
    _json(lib / "listy.json", [])
    _json(lib / "othername.json", seal({**record, "name": "somebody_else"}))
    _json(lib / "version.json", seal({**record, "name": "version", "version": 99}))
    _write(lib / "binary.json", bytes(random.Random(11).randrange(256) for _ in range(512)) + b"\xff")
    (lib / "dirc.json").mkdir()


def setup_saved_noarm(tmp: Path) -> None:
    """A library whose only concept recolours (no arm can carry it out)."""
    from vccjax.sealed import seal

    _json(tmp / "library" / "recolour.json",
          seal({"format": "vccjax-concept", "version": 1, "name": "recolour",
                "program": "scene_parse; top_down_attend; fill_color(blue)"}))


def _pair(folder: Path, key: str, before, after, ext: str = "json") -> None:
    for side, content in (("in", before), ("out", after)):
        path = folder / f"{key}_{side}.{ext}"
        if isinstance(content, bytes):
            _write(path, content)
        elif isinstance(content, str):
            _write(path, content)
        else:
            _json(path, content)


def setup_examples(tmp: Path) -> None:
    e = tmp / "ex"
    red = _scene(("square", "red", 0.5, 0.5, 0.1))
    blue = _scene(("square", "blue", 0.5, 0.5, 0.1))
    _pair(e / "ok", "1", red, blue)
    (e / "empty").mkdir(parents=True)
    _pair(e / "stray", "1", red, blue)
    _write(e / "stray" / "notes.txt", "my notes")
    _write(e / "no_out" / "1_in.json", json.dumps(red))
    _pair(e / "dup_side", "1", red, blue)
    _write(e / "dup_side" / "1_in.png", _one_colour(64, (255, 255, 255)))
    _pair(e / "unreachable", "1", red, _scene(("circle", "blue", 0.5, 0.5, 0.1)))
    _pair(e / "more_objects", "1", red, _scene(("square", "red", 0.5, 0.5, 0.1), ("square", "red", 0.2, 0.2, 0.1)))
    _pair(e / "huge_coord", "1", red,
          '{"objects": [{"shape": "square", "color": "blue", "x": %s, "y": 0.5, "width": 0.1}]}' % LONG_NUMBER)
    _pair(e / "nested", "1", "[" * 100_000 + "]" * 100_000, blue)
    _pair(e / "pointer_nested", "1", {**red, "pointer": [[1], [2]]}, blue)
    _pair(e / "list", "1", [1, 2, 3], blue)
    _pair(e / "blank_images", "1", _one_colour(96, (255, 255, 255)), _one_colour(96, (255, 255, 255)), ext="png")
    _pair(e / "garbage_images", "1", b"\x89PNG garbage", b"\x89PNG garbage", ext="png")
    _pair(e / "binary_json", "1", bytes(random.Random(12).randrange(256) for _ in range(256)), blue)
    (e / "dir_pair" / "1_in.json").mkdir(parents=True)
    _write(e / "dir_pair" / "1_out.json", json.dumps(blue))
    _pair(e / "eleven", "1", {"objects": [{"shape": "circle", "color": "red", "x": 0.05 + 0.09 * i, "y": 0.5,
                                           "width": 0.05} for i in range(11)]}, blue)


def setup_suite(tmp: Path) -> None:
    """A `vcc robot suite` results folder whose per-concept records are corrupt."""
    s = tmp / "suite"
    _write(s / "stack_in_place_horizontal_left.json", "{not json")
    _json(s / "make_the_green_obj_touch_the_red_obj.json", [])
    _write(s / "stack_object_upper_left_corner_vertically.json", "[" * 100_000 + "]" * 100_000)


def setup_bench(tmp: Path) -> None:
    """Folders `vcc bench report` reads: row runs, other runs and arm suites, each corrupt."""
    b = tmp / "b"
    _run_folder(b / "runs_list" / "o1-uniform-0.5M", meta=[])
    _run_folder(b / "runs_badline" / "o1-uniform-0.5M", ["[1, 2, 3]", json.dumps(_record())])
    _run_folder(b / "runs_summary" / "o1-uniform-0.5M")
    _write(b / "runs_summary" / "o1-uniform-0.5M" / "summary.json", "{not json")
    _run_folder(b / "runs_summary_list" / "o1-uniform-0.5M")
    _json(b / "runs_summary_list" / "o1-uniform-0.5M" / "summary.json", [])
    _run_folder(b / "runs_summary_fields" / "o1-uniform-0.5M")
    _json(b / "runs_summary_fields" / "o1-uniform-0.5M" / "summary.json", {"found": "many"})
    _run_folder(b / "others_budget" / "x", meta={"format": "vccjax-induce", "version": 1, "sessions": [],
                                                 "settings": {"order": 1}})
    _run_folder(b / "others_meta_list" / "x", meta=[])
    _json(b / "robot_fields" / "suite" / "summary.json",
          {"source": {"kind": "run", "path": "x"}, "parse": {}, "failures": []})
    _json(b / "robot_types" / "suite" / "summary.json",
          {"source": "run", "parse": "none", "failures": {}, "concepts": 1, "of": 1, "scenarios": 1, "success": 0,
           "rollouts": 0})
    _json(b / "results_bad" / "x.json", {"benchmark": "emulator", "main": [], "sweeps": "none"})
    _json(b / "results_bad" / "y.json", {"benchmark": "search", "batched": None})
    _json(b / "results_bad" / "z.json", {"benchmark": "robot-perception", "conditions": []})


SETUPS = {
    "scenes": setup_scenes, "images": setup_images, "progs": setup_progs, "fifo": setup_fifo, "ds": setup_ds,
    "runs": setup_runs, "libs": setup_libs, "weights": setup_weights, "saved": setup_saved,
    "saved_noarm": setup_saved_noarm, "examples": setup_examples, "suite": setup_suite, "bench": setup_bench,
}


# ---- checks -------------------------------------------------------------------------------
def snapshot(path: Path):
    """None when absent; a file's sha256; a folder's sorted (relative path, sha256) list."""
    if not os.path.lexists(path):
        return None
    if path.is_symlink():
        return ("link", os.readlink(path))
    if path.is_dir():
        return sorted((str(p.relative_to(path)), _sha(p) if p.is_file() and not p.is_symlink() else "-")
                      for p in path.rglob("*"))
    if path.is_file():
        return _sha(path)
    return ("special", path.stat().st_mode)


def describe_change(before, after) -> str:
    """What became of a path in words: created, removed, changed, and for a folder which
    entries came, went or changed."""
    if before is None:
        if isinstance(after, list):
            return "folder created" + (f" holding {', '.join(n for n, _ in after[:6])}" if after else " (empty)")
        return "created"
    if after is None:
        return "removed"
    if isinstance(before, list) and isinstance(after, list):
        b, a = dict(before), dict(after)
        parts = []
        for label, names in (("added", [n for n in a if n not in b]), ("removed", [n for n in b if n not in a]),
                             ("changed", [n for n in a if n in b and a[n] != b[n]])):
            if names:
                parts.append(f"{label} {', '.join(names[:6])}")
        return "; ".join(parts) or "changed"
    if isinstance(before, tuple) and before[0] == "link":
        return "the symlink was replaced" if after != before else "unchanged"
    return "changed"


def leftover_temporaries(tmp: Path) -> list[str]:
    out = []
    for root, dirs, files in os.walk(tmp):
        for name in files + dirs:
            if fnmatch.fnmatch(name, "*.tmp*") or fnmatch.fnmatch(name, ".*.tmp"):
                out.append(str(Path(root, name).relative_to(tmp)))
    return sorted(out)


def exception_type(text: str) -> str | None:
    """The exception a traceback ends with."""
    if "Traceback" not in text:
        return None
    names = re.findall(r"^([A-Za-z_][\w.]*(?:Error|Exception|Exit|Interrupt|Warning|Overflow)\w*)(?::|$)", text,
                       re.MULTILINE)
    return names[-1] if names else "?"


def _limits() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def run_case(case: dict, tmp: Path) -> dict:
    base(tmp)
    setups = case.get("setup") or []
    for name in [setups] if isinstance(setups, str) else setups:
        SETUPS[name](tmp)
    names = templates(tmp)
    argv = [expand(a, names) for a in case["argv"]]
    writes = [Path(expand(w, names)) for w in case.get("writes", [])]
    before = {w: snapshot(w) for w in writes}
    temporaries_before = set(leftover_temporaries(tmp))
    env = {k: v for k, v in os.environ.items() if not k.startswith(("VCC", "PYTEST", "XDG_"))}
    env.update(VCCJAX_CACHE="off", JAX_PLATFORMS="cpu", HOME=str(tmp / "home"), VCC_LIBRARY=str(tmp / "library"),
               PYTHONPATH=str(REPO))
    env.update({k: expand(v, names) for k, v in case.get("env", {}).items()})
    start = time.monotonic()
    proc = subprocess.Popen([sys.executable, "-m", "vcc", *argv], cwd=tmp, env=env, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
                            preexec_fn=_limits)
    hung = False
    try:
        out, err = proc.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        hung = True
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
    seconds = time.monotonic() - start
    out_text, err_text = out.decode(errors="replace"), err.decode(errors="replace")
    lines = [line for line in err_text.strip().splitlines()]
    problems = []
    if hung:
        problems.append(f"hang: still running after {TIMEOUT:.0f} s")
    elif proc.returncode == 0:
        problems.append("exit 0")
    if "Traceback" in out_text + err_text:
        problems.append(f"traceback: {exception_type(out_text + err_text)}")
    crash = re.search(r"internal error[^:]*: ([A-Za-z_][\w.]*)", err_text)
    if crash:  # a crash turned into one line is still a crash: the traceback went to a file
        problems.append(f"internal error: {crash.group(1)}")
    if not hung and (len(lines) != 1 or not lines[0].strip()):
        problems.append(f"stderr has {len(lines)} lines, not one")
    for w in writes:
        after = snapshot(w)
        if after != before[w]:
            problems.append(f"half-written: {w.relative_to(tmp) if w.is_relative_to(tmp) else w}: "
                            f"{describe_change(before[w], after)}")
    left = sorted(set(leftover_temporaries(tmp)) - temporaries_before)
    if left:
        problems.append(f"half-written: temporary files left: {', '.join(left[:5])}")
    result = {"id": case["id"], "argv": argv, "rc": proc.returncode, "seconds": round(seconds, 2),
              "stderr_lines": len(lines), "first": lines[0][:300] if lines else "",
              "last": lines[-1][:300] if lines else "", "stdout_tail": out_text.strip()[-200:],
              "problems": problems, "slow": bool(case.get("slow"))}
    log = os.environ.get("VCC_HOSTILE_LOG")
    if log:
        with open(log, "a") as f:
            f.write(json.dumps(result) + "\n")
    return result


# The default suite runs one quick case in DEFAULT_EVERY (a spread over every command,
# about 1.5 s each); `-m slow` runs all the others, so the two together are the table.
DEFAULT_EVERY = 5


def _param(case: dict, index: int):
    slow = case.get("slow") or index % DEFAULT_EVERY
    return pytest.param(case, id=case["id"], marks=[pytest.mark.slow] if slow else [])


def test_case_ids_are_unique():
    ids = [c["id"] for c in CASES]
    assert len(ids) == len(set(ids)), sorted({i for i in ids if ids.count(i) > 1})
    unknown = {s for c in CASES for s in ([c["setup"]] if isinstance(c.get("setup"), str) else c.get("setup", []))
               if s not in SETUPS}
    assert not unknown, unknown


@pytest.mark.parametrize("case", [_param(c, i) for i, c in enumerate(CASES)])
def test_hostile_input(case, tmp_path):
    r = run_case(case, tmp_path)
    assert not r["problems"], (
        f"{r['id']}: {'; '.join(r['problems'])}\n  argv: {r['argv']}\n  exit {r['rc']} after {r['seconds']} s\n"
        f"  stderr first: {r['first']}\n  stderr last:  {r['last']}"
    )
