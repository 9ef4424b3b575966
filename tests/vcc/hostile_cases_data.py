"""Hostile cases for `vcc dataset build` / `info` and `vcc perception eval`."""

from __future__ import annotations

from tests.vcc.hostile_table import _flags, case

# ---- vcc dataset build / info ---------------------------------------------------------------
DB = ["dataset", "build", "--out", "{tmp}/d"]
case("ds-build-concepts-empty", *DB, "--concepts", "", writes=["{tmp}/d"])
case("ds-build-concepts-commas", *DB, "--concepts", ",,,", writes=["{tmp}/d"])
case("ds-build-concepts-unknown", *DB, "--concepts", "bogus", writes=["{tmp}/d"])
case("ds-build-concepts-mixed", *DB, "--concepts", "remove_top_obj,bogus", writes=["{tmp}/d"])
for name in ("badline", "shipped", "dup", "badprog", "empty", "binary"):
    case(f"ds-build-programs-{name.replace('_', '-')}", *DB, "--programs", f"{{tmp}}/p/list_{name}.txt",
         setup="progs", writes=["{tmp}/d"])
case("ds-build-programs-dir", *DB, "--programs", "{dir}", writes=["{tmp}/d"])
case("ds-build-programs-missing", *DB, "--programs", "{missing}", writes=["{tmp}/d"])
case("ds-build-programs-fifo", *DB, "--programs", "{tmp}/fifo.txt", setup="fifo", writes=["{tmp}/d"], slow=True)
case("ds-build-programs-not-given", *DB, "--programs", "{tmp}/p/list_ok.txt", "--concepts", "remove_top_obj",
     setup="progs", writes=["{tmp}/d"])
case("ds-build-workers-negative", *DB, "--concepts", "remove_top_obj", "--workers", "-1", writes=["{tmp}/d"],
     slow=True)
case("ds-build-seed-negative", *DB, "--concepts", "remove_top_obj", "--seed", "-1", writes=["{tmp}/d"], slow=True)
case("ds-build-seed-nan", *DB, "--concepts", "remove_top_obj", "--seed", "nan", writes=["{tmp}/d"])
case("ds-build-workers-text", *DB, "--concepts", "remove_top_obj", "--workers", "many", writes=["{tmp}/d"])
case("ds-build-out-file", "dataset", "build", "--concepts", "remove_top_obj", "--out", "{file}",
     writes=["{file}"])
case("ds-build-out-ro", "dataset", "build", "--concepts", "remove_top_obj", "--out", "{ro}")
case("ds-build-out-full", "dataset", "build", "--concepts", "remove_top_obj", "--out", "{full}")
case("ds-build-out-empty", "dataset", "build", "--concepts", "remove_top_obj", "--out", "",
     writes=["{tmp}/manifest.json"])
case("ds-build-out-parent-file", "dataset", "build", "--concepts", "remove_top_obj", "--out", "{file}/d",
     writes=["{file}"])
case("ds-build-out-foreign", "dataset", "build", "--concepts", "remove_top_obj", "--out", "{tmp}/ds/foreign",
     setup="ds", writes=["{tmp}/ds/foreign"])
case("ds-build-out-version", "dataset", "build", "--concepts", "remove_top_obj", "--out", "{tmp}/ds/version",
     setup="ds", writes=["{tmp}/ds/version"])
case("ds-build-extra-positional", *DB, "remove_top_obj", writes=["{tmp}/d"])
for name in ("flipped", "garbage_npz", "nan_coords", "shape_index", "short_rows", "missing_keys", "traversal",
             "entry_string", "concepts_list", "manifest_list", "version", "manifest_nested"):
    case(f"ds-info-{name.replace('_', '-')}", "dataset", "info", f"{{tmp}}/ds/{name}", setup="ds")
case("ds-info-file", "dataset", "info", "{file}")
case("ds-info-missing", "dataset", "info", "{missing}")
case("ds-info-none", "dataset", "info")
case("ds-info-two", "dataset", "info", "{shipped}", "{shipped}")

# ---- vcc perception eval --------------------------------------------------------------------
PE = {"images": "1", "styles": "schematic", "size": "64"}
case("pe-styles-empty", "perception", "eval", *_flags(PE, styles=""))
case("pe-styles-commas", "perception", "eval", *_flags(PE, styles=",,"))
case("pe-styles-unknown", "perception", "eval", *_flags(PE, styles="cartoon"))
case("pe-size-small", "perception", "eval", *_flags(PE, size="32"))
case("pe-size-zero", "perception", "eval", *_flags(PE, size="0"))
case("pe-size-negative", "perception", "eval", *_flags(PE, size="-64"))
case("pe-size-text", "perception", "eval", *_flags(PE, size="big"))
case("pe-size-empty", "perception", "eval", *_flags(PE, size=""))
case("pe-size-trailing-comma", "perception", "eval", *_flags(PE, size="64,"))
case("pe-size-float", "perception", "eval", *_flags(PE, size="64.5"))
case("pe-size-huge", "perception", "eval", *_flags(PE, size="1000000000"))
case("pe-images-zero", "perception", "eval", *_flags(PE, images="0"))
case("pe-images-negative", "perception", "eval", *_flags(PE, images="-1"))
case("pe-images-text", "perception", "eval", *_flags(PE, images="lots"))
case("pe-seed-negative", "perception", "eval", *_flags(PE, seed="-1"))
case("pe-pairs-zero", "perception", "eval", *_flags(PE, dataset="{tmp}/ds/ok", pairs="0"), setup="ds")
case("pe-pairs-negative", "perception", "eval", *_flags(PE, dataset="{tmp}/ds/ok", pairs="-1"), setup="ds")
case("pe-workers-zero", "perception", "eval", *_flags(PE, dataset="{tmp}/ds/ok", workers="0"), setup="ds")
case("pe-workers-negative", "perception", "eval", *_flags(PE, dataset="{tmp}/ds/ok", workers="-2"), setup="ds")
for name in ("flipped", "manifest_list", "concepts_list", "nan_coords", "shape_index"):
    case(f"pe-dataset-{name.replace('_', '-')}", "perception", "eval", *_flags(PE, dataset=f"{{tmp}}/ds/{name}"),
         setup="ds", slow=name in ("nan_coords", "shape_index"))
case("pe-dataset-missing", "perception", "eval", *_flags(PE, dataset="{missing}"))
case("pe-dataset-file", "perception", "eval", *_flags(PE, dataset="{file}"))
case("pe-out-ro", "perception", "eval", *_flags(PE, out="{ro}.json"))
case("pe-out-dir", "perception", "eval", *_flags(PE, out="{tmp}/dir.json"), writes=["{tmp}/dir.json"])
case("pe-out-parent-file", "perception", "eval", *_flags(PE, out="{file}/r.json"), writes=["{file}"])
case("pe-out-empty", "perception", "eval", *_flags(PE, out=""))
case("pe-dup-images", "perception", "eval", *_flags(PE), "--images", "2")
