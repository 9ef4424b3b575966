"""Hostile-input fixtures, files: scenes, images, programs, pipes, example folders and
saved concepts (the table is `tests/vcc/hostile_cases.py`, the runner
`tests/vcc/test_hostile_inputs.py`)."""

from __future__ import annotations

import hashlib
import json
import os
import random
import re
import struct
import zlib
from pathlib import Path



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
    # --out folders of an earlier `vcc learn` whose concept.json (read back by a rerun
    # for the programs its question was about) is not one vcc learn wrote
    a = tmp / "asked"
    _write(a / "garbage" / "concept.json", bytes(random.Random(5).randrange(256) for _ in range(200)))
    _json(a / "list" / "concept.json", [])
    _json(a / "bad_program" / "concept.json", {"program": "no_such_op", "rivals": [], "examples": [],
                                               "ambiguous": True})
    _json(a / "rival_types" / "concept.json", {"program": "scene_parse", "rivals": [{"program": 3}],
                                               "examples": [], "ambiguous": True})
    _json(a / "example_types" / "concept.json", {"program": "scene_parse", "rivals": [], "examples": [{"a": 1}],
                                                 "ambiguous": True})
    _json(a / "field_types" / "concept.json", {"program": "scene_parse", "rivals": "none", "examples": [],
                                               "ambiguous": "yes"})
