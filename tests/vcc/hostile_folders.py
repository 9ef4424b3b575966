"""Hostile-input fixtures, folders: datasets, run folders, libraries, weights, suites and
the folders `vcc bench report` reads."""

from __future__ import annotations

import hashlib
import json
import os
import random
import shutil
import time
from pathlib import Path


from tests.vcc.hostile_files import (
    DATASET_CONCEPT, LONG_NUMBER, SHIPPED_DATASET, SHIPPED_LIBRARY, SHIPPED_WEIGHTS, _json, _write, setup_examples,
    setup_fifo, setup_images, setup_progs, setup_saved, setup_saved_noarm, setup_scenes,
)

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
