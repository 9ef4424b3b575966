"""Hostile cases for the command line itself, `vcc run` (program text, scenes, images,
datasets, concepts, numbers) and `vcc trace`."""

from __future__ import annotations

from tests.vcc.hostile_table import case

# ---- the command line itself ---------------------------------------------------------------
case("top-no-command")
case("top-unknown-command", "bogus")
case("top-unknown-flag", "--bogus")
case("top-dataset-no-action", "dataset")
case("top-perception-no-action", "perception")
case("top-argpred-no-action", "argpred")
case("top-robot-no-action", "robot")
case("top-bench-no-action", "bench")
case("top-library-no-action", "library")
case("top-bench-unknown", "bench", "speed")
case("top-argpred-unknown", "argpred", "predict")
case("concepts-two-patterns", "concepts", "a", "b")
case("concepts-unknown-flag", "concepts", "--limit", "3")

# ---- vcc run: program text ------------------------------------------------------------------
REF = ["--engine", "reference"]
for cid, text in [
    ("empty", ""), ("semicolons", ";;;"), ("unknown-op", "scene_parse; jump"),
    ("unclosed", "scene_parse; fill_color(red"), ("unicode", "scene_parse; fill_color(rød)"),
    ("long-body", "scene_parse; loop_start; top_down_attend; " + "fill_color(red); " * 30 + "next_object; loop_end"),
    ("huge-then-bad", "scene_parse; " + "fill_color(red); " * 6000 + "jump"),
    ("newline-garbage", "scene_parse\n\x7f\x01"),
]:
    case(f"run-prog-{cid}", "run", text, *REF)
case("run-prog-dash", "run", "-scene_parse", *REF)
case("run-prog-extra-positional", "run", "scene_parse", "fill_color(red)", *REF)
for name in ("binary", "huge", "dir"):
    case(f"run-progfile-{name}", "run", f"{{tmp}}/p/{name}.vcc", *REF, setup="progs")
case("run-progfile-missing", "run", "{tmp}/nothing.vcc", *REF)
case("run-progfile-fifo", "run", "{tmp}/fifo.vcc", *REF, setup="fifo")

# ---- vcc run: scenes ------------------------------------------------------------------------
for name in (
    "huge_x", "huge_pointer", "x_nan", "nested", "nested_objects", "pointer_nested", "pointer_nulls", "obj_missing",
    "ten_thousand", "overlap", "dir", "loop",
):
    case(f"run-scene-{name.replace('_', '-')}", "run", "scene_parse", *REF, "--scene", f"{{tmp}}/s/{name}.json",
         setup="scenes")
case("run-scene-missing", "run", "scene_parse", *REF, "--scene", "{missing}")
case("run-scene-png", "run", "scene_parse", *REF, "--scene", "{tmp}/img/white.png", setup="images")
case("run-scene-fifo", "run", "scene_parse", *REF, "--scene", "{tmp}/fifo.json", setup="fifo", slow=True)
case("run-scene-and-image", "run", "scene_parse", *REF, "--scene", "{tmp}/s/ok.json", "--image",
     "{tmp}/img/white.png", setup=["scenes", "images"])

# ---- vcc run: images ------------------------------------------------------------------------
for name in ("white.png", "red.png", "empty.png", "bomb.png", "dir.png"):
    case(f"run-image-{name.replace('.', '-')}", "run", "scene_parse", *REF, "--image", f"{{tmp}}/img/{name}",
         setup="images")
case("run-image-missing", "run", "scene_parse", *REF, "--image", "{missing}.png")
case("run-image-json", "run", "scene_parse", *REF, "--image", "{tmp}/s/ok.json", setup="scenes")
case("run-image-fifo", "run", "scene_parse", *REF, "--image", "{tmp}/fifo.png", setup="fifo")

# ---- vcc run: --example, --dataset, --concept and numbers ------------------------------------
EX = ["--concept", "remove_top_obj", "--example", "0", *REF]
for name in ("flipped", "nan_coords", "shape_index", "short_rows", "missing_keys", "entry_string"):
    case(f"run-dataset-{name.replace('_', '-')}", "run", *EX, "--dataset", f"{{tmp}}/ds/{name}", setup="ds")
case("run-dataset-file", "run", *EX, "--dataset", "{file}")
case("run-dataset-missing", "run", *EX, "--dataset", "{missing}")
case("run-example-no-concept", "run", "scene_parse", "--example", "0", *REF)
case("run-example-negative", "run", "--concept", "remove_top_obj", "--example", "-1", *REF)
case("run-example-huge", "run", "--concept", "remove_top_obj", "--example", "1000000000", *REF)
case("run-example-nan", "run", "--concept", "remove_top_obj", "--example", "nan", *REF)
case("run-split-bad", "run", "--concept", "remove_top_obj", "--example", "0", "--split", "valid", *REF)
case("run-concept-empty", "run", "--concept", "", *REF)
case("run-concept-unknown", "run", "--concept", "no_such_concept", *REF)
case("run-concept-path", "run", "--concept", "../../etc/passwd", *REF)
for name in ("notjson", "edited", "badprog", "intprog", "dirc"):
    case(f"run-saved-{name}", "run", "--concept", name, *REF, setup="saved")
case("run-library-is-file", "run", "--concept", "my_concept", *REF, env={"VCC_LIBRARY": "{file}"})
case("run-objects-negative", "run", "scene_parse", "--objects", "-1", *REF)
case("run-objects-eleven", "run", "scene_parse", "--objects", "11", *REF)
case("run-objects-huge", "run", "scene_parse", "--objects", "1000000000", *REF)
case("run-seed-negative", "run", "scene_parse", "--seed", "-1", *REF)
case("run-seed-float", "run", "scene_parse", "--seed", "1.5", *REF)
case("run-engine-bad", "run", "scene_parse", "--engine", "gpu")
case("run-dup-seed", "run", "scene_parse", "--seed", "1", "--seed", "2", *REF)
case("run-dup-concept", "run", "--concept", "remove_top_obj", "--concept", "remove_left_most_obj", *REF)
case("run-dup-scene", "run", "scene_parse", *REF, "--scene", "{tmp}/s/ok.json", "--scene", "{tmp}/s/ok.json",
     setup="scenes")

# ---- vcc trace ------------------------------------------------------------------------------
T = ["trace", "scene_parse; set_color_attn(red); top_down_attend"]
case("trace-out-missing", *T)
case("trace-out-txt", *T, "--out", "{tmp}/t.txt", writes=["{tmp}/t.txt"])
case("trace-out-no-suffix", *T, "--out", "{tmp}/trace", writes=["{tmp}/trace"])
case("trace-out-empty", *T, "--out", "")
case("trace-out-commas", *T, "--out", ",,")
case("trace-out-mixed", *T, "--out", "{tmp}/a.png,{tmp}/b.txt", writes=["{tmp}/a.png", "{tmp}/b.txt"])
case("trace-out-ro", *T, "--out", "{ro}.png")
case("trace-out-dir", *T, "--out", "{tmp}/dir.png", writes=["{tmp}/dir.png"])
case("trace-out-parent-file", *T, "--out", "{file}/t.png", writes=["{file}"])
case("trace-out-half-dir", *T, "--out", "{tmp}/a.png,{tmp}/dir.gif", writes=["{tmp}/a.png"])
case("trace-out-half-ro", *T, "--out", "{tmp}/a.gif,{ro}.png", writes=["{tmp}/a.gif"])
case("trace-out-dup", *T, "--out", "{tmp}/a.png", "--out", "{tmp}/b.png", writes=["{tmp}/a.png", "{tmp}/b.png"])
case("trace-size-zero", *T, "--out", "{tmp}/t.png", "--size", "0", writes=["{tmp}/t.png"])
case("trace-size-negative", *T, "--out", "{tmp}/t.png", "--size", "-256", writes=["{tmp}/t.png"])
case("trace-size-huge", *T, "--out", "{tmp}/t.png", "--size", "1000000000", writes=["{tmp}/t.png"])
case("trace-columns-zero", *T, "--out", "{tmp}/t.png", "--columns", "0", writes=["{tmp}/t.png"])
case("trace-seconds-zero", *T, "--out", "{tmp}/t.gif", "--seconds", "0", writes=["{tmp}/t.gif"])
case("trace-seconds-nan", *T, "--out", "{tmp}/t.gif", "--seconds", "nan", writes=["{tmp}/t.gif"])
case("trace-seconds-inf", *T, "--out", "{tmp}/t.gif", "--seconds", "inf", writes=["{tmp}/t.gif"])
case("trace-prog-bad", "trace", "scene_parse; jump", "--out", "{tmp}/t.png", writes=["{tmp}/t.png"])
for name in ("huge_x", "pointer_nested", "nested"):
    case(f"trace-scene-{name.replace('_', '-')}", *T, "--scene", f"{{tmp}}/s/{name}.json", "--out", "{tmp}/t.png",
         setup="scenes", writes=["{tmp}/t.png"])
case("trace-image-white", *T, "--image", "{tmp}/img/white.png", "--out", "{tmp}/t.png", setup="images",
     writes=["{tmp}/t.png"])
case("trace-dataset-flipped", "trace", "--concept", "remove_top_obj", "--example", "0", "--dataset",
     "{tmp}/ds/flipped", "--out", "{tmp}/t.png", setup="ds", writes=["{tmp}/t.png"])
