"""Hostile input for every `vcc` command: the table `test_hostile_inputs.py` runs.

Each case: {"id", "argv", optional "setup" (a name or list of names of the runner's
SETUPS), optional "writes" (output paths that must be left absent or as they were),
optional "env" (extra environment), optional "slow"}. Every case must fail: non-zero
exit, no traceback, exactly one line on stderr, within the timeout, nothing half-written.

Templates in argv, writes and env (the runner's `templates`):
  {tmp}      the case's own folder (also the cwd; HOME is {tmp}/home, VCC_LIBRARY {tmp}/library)
  {file}     an existing regular file          {dir}    an existing empty folder
  {empty}    an empty file                     {bin}    a file of random bytes
  {missing}  a path that does not exist        {full}   /dev/full
  {ro}       a path that cannot be created (under /proc); {ro_dir} its parent
  {shipped}  the shipped dataset folder        {repo}   the repository
Every case folder also holds dir.<ext> (a folder where a file is meant) for ext in png,
gif, json, mp4, jpg, msgpack. {full} is given only where a folder is meant: given as a
file to write, an atomic writer running as root would rename its temporary file over
the device node.
Setups (files under {tmp}): scenes -> s/*.json; images -> img/*; progs -> p/*.vcc and
p/list_*.txt (`name: program` lines); fifo -> fifo.{json,txt,vcc,png} (named pipes: a
read blocks); ds -> ds/<variant> (one-concept datasets, each corrupt in one way);
runs -> runs/<variant> (induce run folders) and runs/models/*.json (model-K.json);
libs -> lib/*.json (library files); weights -> w/*.msgpack (+ .json cards);
saved, saved_noarm -> the user's saved concepts; examples -> ex/<variant> (vcc learn
pairs); suite -> suite/ (a robot suite folder); bench -> b/* (what bench report reads).

Cheap settings keep a case from doing real work should a check be missing: induce
and learn cases search one concept with a budget of 1 or 2000 on uniform models;
argpred train draws one program for one epoch; robot run/suite/stress and argpred
train cases run with JAX unable to start (NO_DEVICE), so a missing check ends in a
crash the case reports, never in training or rollouts. A few cases whose bad input
would otherwise start long work carry a second fault that stops it (said where).
"""

from __future__ import annotations


def _flags(defaults: dict, **over) -> list[str]:
    """Command-line flags from `defaults` with `over` replacing (None drops one)."""
    merged = {**defaults, **over}
    argv: list[str] = []
    for k, v in merged.items():
        if v is None or v is False:
            continue
        flag = "--" + k.rstrip("_").replace("_", "-")
        argv += [flag] if v is True else [flag, str(v)]
    return argv


CASES: list[dict] = []


def case(id: str, *argv: str, setup=None, writes=None, slow: bool = False, env=None) -> None:
    c: dict = {"id": id, "argv": list(argv)}
    if setup:
        c["setup"] = setup
    if writes:
        c["writes"] = list(writes)
    if slow:
        c["slow"] = True
    if env:
        c["env"] = env
    CASES.append(c)


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

# ---- vcc induce -----------------------------------------------------------------------------
IN = {"concepts": "remove_top_obj", "budget": "1", "args": "uniform", "iterations": "1", "width": "1",
      "quiet": True, "out": "{tmp}/run"}
W_RUN = ["{tmp}/run"]
case("induce-budget-zero", "induce", *_flags(IN, budget="0"), writes=W_RUN)
case("induce-budget-negative", "induce", *_flags(IN, budget="-5"), writes=W_RUN)
case("induce-budget-nan", "induce", *_flags(IN, budget="nan"), writes=W_RUN)
case("induce-budget-float", "induce", *_flags(IN, budget="1.5"), writes=W_RUN)
case("induce-order-2", "induce", *_flags(IN, order="2"), writes=W_RUN)
case("induce-args-bad", "induce", *_flags(IN, args="psychic"), writes=W_RUN)
case("induce-subroutines-bad", "induce", *_flags(IN, subroutines="maybe"), writes=W_RUN)
case("induce-epsilon-nan", "induce", *_flags(IN, epsilon="nan"), writes=W_RUN, slow=True)
case("induce-epsilon-negative", "induce", *_flags(IN, epsilon="-1"), writes=W_RUN, slow=True)
# --epsilon 0 is no hostile input: a model without smoothing is a setting one may choose
case("induce-epsilon-inf", "induce", *_flags(IN, epsilon="inf"), writes=W_RUN, slow=True)
case("induce-iterations-zero", "induce", *_flags(IN, iterations="0"), writes=W_RUN, slow=True)
case("induce-iterations-negative", "induce", *_flags(IN, iterations="-1"), writes=W_RUN, slow=True)
case("induce-width-zero", "induce", *_flags(IN, width="0"), writes=W_RUN, slow=True)
case("induce-width-negative", "induce", *_flags(IN, width="-4"), writes=W_RUN, slow=True)
case("induce-seed-negative", "induce", *_flags(IN, seed="-1"), writes=W_RUN, slow=True)
case("induce-workers-without-cluster", "induce", *_flags(IN, workers="2"), writes=W_RUN)
case("induce-cluster-bad", "induce", *_flags(IN, cluster="spark"), writes=W_RUN)
case("induce-cluster-workers-zero", "induce", *_flags(IN, cluster="ray", workers="0"), writes=W_RUN, slow=True)
case("induce-concepts-empty", "induce", *_flags(IN, concepts=""), writes=W_RUN)
case("induce-concepts-commas", "induce", *_flags(IN, concepts=",,"), writes=W_RUN)
case("induce-concepts-unknown", "induce", *_flags(IN, concepts="bogus"), writes=W_RUN)
case("induce-concepts-mixed", "induce", *_flags(IN, concepts="remove_top_obj,bogus"), writes=W_RUN)
case("induce-out-missing", "induce", *_flags(IN, out=None))
case("induce-out-file", "induce", *_flags(IN, out="{file}"), writes=["{file}"])
case("induce-out-ro", "induce", *_flags(IN, out="{ro}"))
case("induce-out-full", "induce", *_flags(IN, out="{full}"))
case("induce-out-empty", "induce", *_flags(IN, out=""), writes=["{tmp}/run.json", "{tmp}/results.jsonl"])
case("induce-out-parent-file", "induce", *_flags(IN, out="{file}/run"), writes=["{file}"])
for name in ("line_list", "line_iter_str", "results_binary", "meta_list", "meta_missing"):
    case(f"induce-resume-{name.replace('_', '-')}", "induce", *_flags(IN, out=f"{{tmp}}/runs/{name}"),
         setup="runs", writes=[f"{{tmp}}/runs/{name}"])
for name in ("wrong_shape", "nan", "subroutines_bad", "logp_huge"):
    case(f"induce-model-{name.replace('_', '-')}", "induce", *_flags(IN, model=f"{{tmp}}/runs/models/{name}.json"),
         setup="runs", writes=W_RUN)
case("induce-model-missing", "induce", *_flags(IN, model="{missing}"), writes=W_RUN)
case("induce-model-dir", "induce", *_flags(IN, model="{dir}"), writes=W_RUN)
case("induce-model-fifo", "induce", *_flags(IN, model="{tmp}/fifo.json"), setup="fifo", writes=W_RUN, slow=True)
for name in ("edited", "neg_counts", "epsilon_nan"):
    case(f"induce-model-lib-{name.replace('_', '-')}", "induce", *_flags(IN, model=f"{{tmp}}/lib/{name}.json"),
         setup="libs", writes=W_RUN, slow=name != "edited")
case("induce-model-library-order-0", "induce", *_flags(IN, model="library", order="0"), writes=W_RUN)
for name in ("manifest_list", "missing_keys"):
    case(f"induce-dataset-{name.replace('_', '-')}", "induce", *_flags(IN, dataset=f"{{tmp}}/ds/{name}"),
         setup="ds", writes=W_RUN)
for name in ("flipped", "no_program"):
    case(f"induce-dataset-oracle-{name.replace('_', '-')}", "induce",
         *_flags(IN, dataset=f"{{tmp}}/ds/{name}", args="oracle"), setup="ds", writes=W_RUN)
case("induce-dataset-no-concepts", "induce", *_flags(IN, dataset="{tmp}/ds/concepts_none", concepts="all"),
     setup="ds", writes=W_RUN)
case("induce-dataset-demo", "induce", *_flags(IN, dataset="{tmp}/ds/ok", concepts="demo"), setup="ds",
     writes=W_RUN)
case("induce-dataset-missing", "induce", *_flags(IN, dataset="{missing}"), writes=W_RUN)

# ---- vcc learn ------------------------------------------------------------------------------
LE = {"out": "{tmp}/out", "library": "uniform", "args": "uniform", "engine": "reference", "budget": "2000",
      "rival_budget": "0", "fresh_scenes": "1", "quiet": True}
W_OUT = ["{tmp}/out"]
for name in ("empty", "stray", "unreachable", "huge_coord", "nested", "blank_images"):
    case(f"learn-ex-{name.replace('_', '-')}", "learn", f"{{tmp}}/ex/{name}", *_flags(LE), setup="examples",
         writes=W_OUT)
case("learn-ex-file", "learn", "{file}", *_flags(LE), writes=W_OUT)
case("learn-ex-missing", "learn", "{missing}", *_flags(LE), writes=W_OUT)
case("learn-ex-none", "learn", *_flags(LE), writes=W_OUT)
EXOK = "{tmp}/ex/ok"
case("learn-out-file", "learn", EXOK, *_flags(LE, out="{file}"), setup="examples", writes=["{file}"])
case("learn-out-ro", "learn", EXOK, *_flags(LE, out="{ro}"), setup="examples")
case("learn-out-full", "learn", EXOK, *_flags(LE, out="{full}"), setup="examples")  # a folder path that is a device
case("learn-out-empty", "learn", EXOK, *_flags(LE, out=""), setup="examples",
     writes=["{tmp}/concept.json", "{tmp}/trace.png"])
case("learn-out-parent-file", "learn", EXOK, *_flags(LE, out="{file}/out"), setup="examples", writes=["{file}"])
case("learn-out-missing", "learn", EXOK, *_flags(LE, out=None), setup="examples")
for name in ("garbage", "list", "bad_program", "rival_types", "example_types", "field_types"):  # a rerun reads the old question
    case(f"learn-asked-{name.replace('_', '-')}", "learn", EXOK, *_flags(LE, out=f"{{tmp}}/asked/{name}"),
         setup="examples", writes=[f"{{tmp}}/asked/{name}/concept.json"])
case("learn-budget-zero", "learn", EXOK, *_flags(LE, budget="0"), setup="examples", writes=W_OUT)
case("learn-budget-negative", "learn", EXOK, *_flags(LE, budget="-1"), setup="examples", writes=W_OUT)
case("learn-budget-nan", "learn", EXOK, *_flags(LE, budget="nan"), setup="examples", writes=W_OUT)
case("learn-rival-negative", "learn", EXOK, *_flags(LE, rival_budget="-1"), setup="examples", writes=W_OUT)
case("learn-parts-zero", "learn", EXOK, *_flags(LE, parts="0"), setup="examples", writes=W_OUT)
case("learn-parts-many", "learn", EXOK, *_flags(LE, parts="6"), setup="examples", writes=W_OUT)
case("learn-fresh-zero", "learn", EXOK, *_flags(LE, fresh_scenes="0"), setup="examples", writes=W_OUT)
case("learn-fresh-negative", "learn", EXOK, *_flags(LE, fresh_scenes="-10"), setup="examples", writes=W_OUT)
case("learn-seed-negative", "learn", EXOK, *_flags(LE, seed="-1"), setup="examples", writes=W_OUT, slow=True)
case("learn-fixate-empty", "learn", EXOK, *_flags(LE, fixate=""), setup="examples", writes=W_OUT)
case("learn-fixate-commas", "learn", EXOK, *_flags(LE, fixate=",,"), setup="examples", writes=W_OUT)
case("learn-fixate-bad", "learn", EXOK, *_flags(LE, fixate="sideways"), setup="examples", writes=W_OUT)
case("learn-fixate-mixed", "learn", EXOK, *_flags(LE, fixate="left,up"), setup="examples", writes=W_OUT)
for name in ("garbage", "edited", "subs_unknown", "dir", "neg_counts", "epsilon_nan"):
    case(f"learn-library-{name.replace('_', '-')}", "learn", EXOK, *_flags(LE, library=f"{{tmp}}/lib/{name}.json"),
         setup=["examples", "libs"], writes=W_OUT, slow=name in ("neg_counts", "epsilon_nan"))
case("learn-library-missing", "learn", EXOK, *_flags(LE, library="{missing}"), setup="examples", writes=W_OUT)
case("learn-library-fifo", "learn", EXOK, *_flags(LE, library="{tmp}/fifo.json"), setup=["examples", "fifo"],
     writes=W_OUT, slow=True)
case("learn-args-oracle", "learn", EXOK, *_flags(LE, args="oracle"), setup="examples", writes=W_OUT)
case("learn-engine-bad", "learn", EXOK, *_flags(LE, engine="gpu"), setup="examples", writes=W_OUT)
case("learn-name-bad", "learn", EXOK, *_flags(LE, name="Bad Name", save=True), setup="examples", writes=W_OUT)
case("learn-name-shipped", "learn", EXOK, *_flags(LE, name="remove_top_obj", save=True), setup="examples",
     writes=W_OUT)
case("learn-name-empty", "learn", EXOK, *_flags(LE, name="", save=True), setup="examples", writes=W_OUT)
case("learn-name-long", "learn", EXOK, *_flags(LE, name="a" * 65, save=True), setup="examples", writes=W_OUT)
case("learn-save-no-name", "learn", EXOK, *_flags(LE, save=True), setup="examples", writes=W_OUT)
case("learn-save-library-file", "learn", EXOK, *_flags(LE, name="my_concept", save=True), setup="examples",
     writes=W_OUT, env={"VCC_LIBRARY": "{file}"})
case("learn-save-library-ro", "learn", EXOK, *_flags(LE, name="my_concept", save=True), setup="examples",
     writes=W_OUT, env={"VCC_LIBRARY": "{ro}"})

# ---- vcc library build / show ---------------------------------------------------------------
LB = ["library", "build", "--out", "{tmp}/lib.json"]
for name in ("line_list", "line_found_str", "line_program_null", "line_program_bad", "line_huge_dl",
             "only_unfound", "meta_list", "meta_missing"):
    case(f"lib-build-{name.replace('_', '-')}", *LB, "--from", f"{{tmp}}/runs/{name}", setup="runs",
         writes=["{tmp}/lib.json"])
case("lib-build-from-missing", *LB, "--from", "{missing}", writes=["{tmp}/lib.json"])
case("lib-build-from-empty-dir", *LB, "--from", "{dir}", writes=["{tmp}/lib.json"])
case("lib-build-from-none", *LB, writes=["{tmp}/lib.json"])
RUN_OK = "{tmp}/runs/ok"
case("lib-build-out-ro", "library", "build", "--from", RUN_OK, "--out", "{ro}.json", setup="runs")
case("lib-build-out-dir", "library", "build", "--from", RUN_OK, "--out", "{tmp}/dir.json", setup="runs",
     writes=["{tmp}/dir.json"])
case("lib-build-out-parent-file", "library", "build", "--from", RUN_OK, "--out", "{file}/lib.json", setup="runs",
     writes=["{file}"])
case("lib-build-out-empty", "library", "build", "--from", RUN_OK, "--out", "", setup="runs")
case("lib-build-out-is-run", "library", "build", "--from", RUN_OK, "--out", RUN_OK, setup="runs",
     writes=[RUN_OK])
for name in ("garbage", "foreign", "edited", "neg_counts", "order_7", "epsilon_nan", "subs_unknown",
             "card_settings_list", "nested"):
    case(f"lib-show-{name.replace('_', '-')}", "library", "show", f"{{tmp}}/lib/{name}.json", setup="libs")
case("lib-show-missing", "library", "show", "{missing}")
case("lib-show-empty", "library", "show", "{empty}")
case("lib-show-fifo", "library", "show", "{tmp}/fifo.json", setup="fifo", slow=True)
case("lib-show-show-negative", "library", "show", "--show", "-1")
case("lib-show-show-nan", "library", "show", "--show", "nan")
case("lib-show-dup-show", "library", "show", "--show", "1", "--show", "2")
case("lib-show-two-paths", "library", "show", "{file}", "{file}")

# ---- vcc argpred data / train / eval ---------------------------------------------------------
NO_DEVICE = {"JAX_PLATFORMS": "hostile-no-device"}  # JAX cannot start: no training, no rollout
AD = {"out": "{tmp}/ad", "programs": "1", "quiet": True}
W_AD = ["{tmp}/ad"]
case("ap-data-programs-zero", "argpred", "data", *_flags(AD, programs="0"), writes=W_AD)
case("ap-data-programs-negative", "argpred", "data", *_flags(AD, programs="-3"), writes=W_AD)
case("ap-data-programs-text", "argpred", "data", *_flags(AD, programs="ten"), writes=W_AD)
case("ap-data-joined-negative", "argpred", "data", *_flags(AD, joined="-0.1"), writes=W_AD)
case("ap-data-joined-over", "argpred", "data", *_flags(AD, joined="1.5"), writes=W_AD)
case("ap-data-joined-nan", "argpred", "data", *_flags(AD, joined="nan"), writes=W_AD)
case("ap-data-joined-inf", "argpred", "data", *_flags(AD, joined="inf"), writes=W_AD)
case("ap-data-workers-negative", "argpred", "data", *_flags(AD, workers="-1"), writes=W_AD)
case("ap-data-kind-bad", "argpred", "data", *_flags(AD, kind="painted"), writes=W_AD)
case("ap-data-seed-negative", "argpred", "data", *_flags(AD, seed="-1"), writes=W_AD, slow=True)
case("ap-data-out-missing", "argpred", "data", *_flags(AD, out=None))
case("ap-data-out-file", "argpred", "data", *_flags(AD, out="{file}"), writes=["{file}"])
case("ap-data-out-ro", "argpred", "data", *_flags(AD, out="{ro}"))
case("ap-data-out-full", "argpred", "data", *_flags(AD, out="{full}"))
case("ap-data-out-empty", "argpred", "data", *_flags(AD, out=""))
case("ap-data-out-parent-file", "argpred", "data", *_flags(AD, out="{file}/ad"), writes=["{file}"])
# train: one program, one epoch, one member, no carry programs; JAX cannot start (NO_DEVICE), so that a
# missing check ends in a crash the case reports instead of in training
AT = {"out": "{tmp}/w.msgpack", "data": "{tmp}/ad", "programs": "1", "epochs": "1", "members": "1", "carry": "0",
      "quiet": True}
W_AT = ["{tmp}/w.msgpack", "{tmp}/w.json", "{tmp}/w.ckpt"]
for cid, over in [
    ("epochs-zero", {"epochs": "0"}), ("batch-zero", {"batch": "0"}), ("kernel-zero", {"kernel": "0"}),
    ("depth-zero", {"depth": "0"}), ("members-zero", {"members": "0"}), ("hidden-negative", {"hidden": "-1"}),
    ("carry-negative", {"carry": "-1"}), ("workers-negative", {"workers": "-1"}), ("programs-zero", {"programs": "0"}),
    ("joined-over", {"joined": "2"}), ("lr-zero", {"lr": "0"}), ("lr-negative", {"lr": "-0.1"}),
    ("lr-nan", {"lr": "nan"}), ("lr-inf", {"lr": "inf"}), ("pw-zero", {"positive_weight": "0"}),
    ("pw-nan", {"positive_weight": "nan"}), ("l1-negative", {"l1": "-1"}), ("l1-nan", {"l1": "nan"}),
    ("bias-nan", {"bias_start": "nan"}), ("bias-inf", {"bias_start": "-inf"}), ("evidence-bad", {"evidence": "vibes"}),
    ("epochs-text", {"epochs": "thirty"}), ("hidden-huge", {"hidden": "1000000000"}),
    ("kernel-huge", {"kernel": "1000000000"}), ("members-huge", {"members": "1000000000"}),
    ("out-dir", {"out": "{tmp}/dir.msgpack"}), ("out-ro", {"out": "{ro}.msgpack"}),
    ("out-parent-file", {"out": "{file}/w.msgpack"}), ("out-empty", {"out": ""}),
    ("data-two-missing", {"data": "{tmp}/nodata1,{tmp}/nodata2"}), ("data-file", {"data": "{file},{dir}"}),
]:
    case(f"ap-train-{cid}", "argpred", "train", *_flags(AT, **over), writes=W_AT + ["{tmp}/ad"], env=NO_DEVICE)
AE = {"concepts": "remove_top_obj"}
for name in ("garbage", "msgpack_int", "flipped", "huge_hidden", "zero_kernel", "members_str", "card_list",
             "no_card"):
    case(f"ap-eval-weights-{name.replace('_', '-')}", "argpred", "eval",
         *_flags(AE, weights=f"{{tmp}}/w/{name}.msgpack"), setup="weights",
         slow=name in ("huge_hidden", "huge_kernel", "negative_hidden", "zero_kernel"))
case("ap-eval-weights-missing", "argpred", "eval", *_flags(AE, weights="{missing}"))
case("ap-eval-weights-plain-file", "argpred", "eval", *_flags(AE, weights="{file}"))
case("ap-eval-concepts-empty", "argpred", "eval", *_flags(AE, concepts=""))
case("ap-eval-concepts-unknown", "argpred", "eval", *_flags(AE, concepts="bogus"))
for name in ("flipped", "nan_coords", "shape_index"):
    case(f"ap-eval-dataset-{name.replace('_', '-')}", "argpred", "eval", *_flags(AE, dataset=f"{{tmp}}/ds/{name}"),
         setup="ds", slow=True)
case("ap-eval-dataset-missing", "argpred", "eval", *_flags(AE, dataset="{missing}"))
case("ap-eval-out-ro", "argpred", "eval", *_flags(AE, out="{ro}.json"), slow=True)
case("ap-eval-out-dir", "argpred", "eval", *_flags(AE, out="{tmp}/dir.json"), writes=["{tmp}/dir.json"], slow=True)
case("ap-eval-out-parent-file", "argpred", "eval", *_flags(AE, out="{file}/r.json"), writes=["{file}"], slow=True)
case("ap-eval-record-concepts", "argpred", "eval", *_flags(AE, record=True))
case("ap-eval-show-negative", "argpred", "eval", *_flags(AE, show="-1"))
case("ap-eval-show-text", "argpred", "eval", *_flags(AE, show="all"))

# ---- vcc robot run / suite / perception / stress ----------------------------------------------
# Every run, suite and stress case runs with NO_DEVICE: should a check be missing, the case
# ends in a crash where the first rollout would start (and is reported), never in rollouts.
ARM = "stack_in_place_horizontal_left"
RR = ["robot", "run", "--concept", ARM, "--scenarios", "1"]


def robot(id: str, *argv: str, **kw) -> None:
    case(id, *argv, env=NO_DEVICE, **kw)


robot("robot-run-concept-missing", "robot", "run")
robot("robot-run-concept-unknown", "robot", "run", "--concept", "bogus", "--scenarios", "1")
robot("robot-run-concept-empty", "robot", "run", "--concept", "", "--scenarios", "1")
robot("robot-run-concept-plus-empty", "robot", "run", "--concept", ARM + "+", "--scenarios", "1")
robot("robot-run-concept-plus-only", "robot", "run", "--concept", "+", "--scenarios", "1")
robot("robot-run-concept-not-arm", "robot", "run", "--concept", "change_all_objs_color", "--scenarios", "1")
robot("robot-run-program-bad", *RR, "--program", "scene_parse; jump")
robot("robot-run-program-fill", *RR, "--program", "scene_parse; top_down_attend; fill_color(red)")
robot("robot-run-program-empty", *RR, "--program", "")
for name in ("binary", "empty", "dir"):
    robot(f"robot-run-progfile-{name}", *RR, "--program", f"{{tmp}}/p/{name}.vcc", setup="progs")
robot("robot-run-video-txt", *RR, "--video", "{tmp}/v.txt", writes=["{tmp}/v.txt"])
robot("robot-run-video-gif", *RR, "--video", "{tmp}/v.gif", writes=["{tmp}/v.gif"])
robot("robot-run-frames-txt", *RR, "--frames", "{tmp}/f.txt", writes=["{tmp}/f.txt"])
robot("robot-run-scenarios-zero", "robot", "run", "--concept", ARM, "--scenarios", "0")
robot("robot-run-scenarios-negative", "robot", "run", "--concept", ARM, "--scenarios", "-4")
robot("robot-run-seed-negative", *RR, "--seed", "-1", slow=True)
for name in ("line_list", "line_program_int", "results_dir", "only_unfound"):
    robot(f"robot-run-induced-{name.replace('_', '-')}", "robot", "run", "--concept", "remove_top_obj",
          "--scenarios", "1", "--induced", f"{{tmp}}/runs/{name}", setup="runs")
robot("robot-run-induced-missing", *RR, "--induced", "{missing}")
for name in ("badprog", "notjson", "intprog"):
    robot(f"robot-run-saved-{name}", "robot", "run", "--concept", name, "--scenarios", "1", setup="saved")
# output paths a run writes only after its rollouts: they must be refused before
robot("robot-run-json-ro", *RR, "--json", "{ro}.json", slow=True)
robot("robot-run-json-dir", *RR, "--json", "{tmp}/dir.json", writes=["{tmp}/dir.json"], slow=True)
robot("robot-run-video-ro", *RR, "--video", "{ro}.mp4", slow=True)
robot("robot-run-video-dir", *RR, "--video", "{tmp}/dir.mp4", writes=["{tmp}/dir.mp4"], slow=True)
robot("robot-run-frames-parent-file", *RR, "--frames", "{file}/f.png", writes=["{file}"], slow=True)
RS = {"out": "{tmp}/rs", "concepts": ARM, "scenarios": "1"}
robot("robot-suite-out-missing", "robot", "suite", *_flags(RS, out=None))
robot("robot-suite-workers-without-cluster", "robot", "suite", *_flags(RS, workers="2"), writes=["{tmp}/rs"])
robot("robot-suite-cluster-bad", "robot", "suite", *_flags(RS, cluster="dask"), writes=["{tmp}/rs"])
robot("robot-suite-cluster-shard", "robot", "suite", *_flags(RS, cluster="ray", shard="0/2"), writes=["{tmp}/rs"])
robot("robot-suite-count-zero", "robot", "suite", *_flags(RS, concepts=None, count="0"), writes=["{tmp}/rs"])
robot("robot-suite-count-negative", "robot", "suite", *_flags(RS, concepts=None, count="-1"), writes=["{tmp}/rs"])
robot("robot-suite-scenarios-zero", "robot", "suite", *_flags(RS, scenarios="0"), writes=["{tmp}/rs"])
robot("robot-suite-scenarios-negative", "robot", "suite", *_flags(RS, scenarios="-8"), writes=["{tmp}/rs"])
for cid, shard in [("1-of-1", "1/1"), ("letters", "a/b"), ("three-parts", "0/2/3"), ("empty", "")]:
    robot(f"robot-suite-shard-{cid}", "robot", "suite", *_flags(RS, shard=shard), writes=["{tmp}/rs"])
robot("robot-suite-concepts-empty", "robot", "suite", *_flags(RS, concepts=""), writes=["{tmp}/rs"])
robot("robot-suite-concepts-commas", "robot", "suite", *_flags(RS, concepts=",,,"), writes=["{tmp}/rs"])
robot("robot-suite-concepts-unknown", "robot", "suite", *_flags(RS, concepts="bogus"), writes=["{tmp}/rs"])
robot("robot-suite-concepts-not-arm", "robot", "suite", *_flags(RS, concepts="change_all_objs_color"),
      writes=["{tmp}/rs"])
robot("robot-suite-source-missing", "robot", "suite", *_flags(RS, source="{missing}"), writes=["{tmp}/rs"])
robot("robot-suite-source-file", "robot", "suite", *_flags(RS, source="{file}"), writes=["{tmp}/rs"])
for name in ("line_list", "results_dir", "only_unfound"):
    robot(f"robot-suite-source-{name.replace('_', '-')}", "robot", "suite",
          *_flags(RS, concepts=None, source=f"{{tmp}}/runs/{name}"), setup="runs", writes=["{tmp}/rs"])
robot("robot-suite-source-library-empty", "robot", "suite", *_flags(RS, concepts=None, source="library"),
      writes=["{tmp}/rs"])
robot("robot-suite-source-library-noarm", "robot", "suite", *_flags(RS, concepts=None, source="library"),
      setup="saved_noarm", writes=["{tmp}/rs"])
robot("robot-suite-source-library-corrupt", "robot", "suite", *_flags(RS, concepts=None, source="library"),
      setup="saved", writes=["{tmp}/rs"])
robot("robot-suite-out-file", "robot", "suite", *_flags(RS, out="{file}"), writes=["{file}"])
robot("robot-suite-out-ro", "robot", "suite", *_flags(RS, out="{ro}"))
robot("robot-suite-status-out-missing", "robot", "suite", *_flags(RS, status=True), writes=["{tmp}/rs"])
robot("robot-suite-status-out-file", "robot", "suite", *_flags(RS, status=True, out="{file}"), writes=["{file}"])
robot("robot-suite-status-corrupt", "robot", "suite", "--status", "--out", "{tmp}/suite", "--source", "reference",
      "--concepts", "stack_in_place_horizontal_left,make_the_green_obj_touch_the_red_obj,"
                    "stack_object_upper_left_corner_vertically", setup="suite", writes=["{tmp}/suite"])
RP = {"out": "{tmp}/rp.json", "scenes": "1"}
case("robot-perception-scenes-zero", "robot", "perception", *_flags(RP, scenes="0"), writes=["{tmp}/rp.json"])
case("robot-perception-scenes-negative", "robot", "perception", *_flags(RP, scenes="-1"), writes=["{tmp}/rp.json"])
case("robot-perception-scenes-nan", "robot", "perception", *_flags(RP, scenes="nan"), writes=["{tmp}/rp.json"])
case("robot-perception-out-missing", "robot", "perception", *_flags(RP, out=None))
case("robot-perception-out-txt", "robot", "perception", *_flags(RP, out="{tmp}/rp.txt"), writes=["{tmp}/rp.txt"])
case("robot-perception-out-no-suffix", "robot", "perception", *_flags(RP, out="{tmp}/rp"), writes=["{tmp}/rp"])
case("robot-perception-out-empty", "robot", "perception", *_flags(RP, out=""))
case("robot-perception-out-ro", "robot", "perception", *_flags(RP, out="{ro}.json"), slow=True)
case("robot-perception-out-dir", "robot", "perception", *_flags(RP, out="{tmp}/dir.json"),
     writes=["{tmp}/dir.json"], slow=True)
case("robot-perception-out-parent-file", "robot", "perception", *_flags(RP, out="{file}/rp.json"),
     writes=["{file}"], slow=True)
case("robot-perception-seed-negative", "robot", "perception", *_flags(RP, seed="-1"), writes=["{tmp}/rp.json"],
     slow=True)
ST = {"out": "{tmp}/st", "rollouts": "1"}
robot("robot-stress-rollouts-zero", "robot", "stress", *_flags(ST, rollouts="0"), writes=["{tmp}/st"])
robot("robot-stress-rollouts-negative", "robot", "stress", *_flags(ST, rollouts="-32"), writes=["{tmp}/st"])
robot("robot-stress-rollouts-text", "robot", "stress", *_flags(ST, rollouts="many"), writes=["{tmp}/st"])
robot("robot-stress-out-missing", "robot", "stress", *_flags(ST, out=None))
robot("robot-stress-source-missing", "robot", "stress", *_flags(ST, source="{missing}"), writes=["{tmp}/st"])
robot("robot-stress-source-file", "robot", "stress", *_flags(ST, source="{file}"), writes=["{tmp}/st"])
robot("robot-stress-source-bad-line", "robot", "stress", *_flags(ST, source="{tmp}/runs/line_list"), setup="runs",
      writes=["{tmp}/st"])
# an empty library can start no rollout; unguarded, since the arm's model is built (on JAX) before the draw
case("robot-stress-source-library-empty", "robot", "stress", *_flags(ST, source="library"), writes=["{tmp}/st"],
     slow=True)
robot("robot-stress-out-file", "robot", "stress", *_flags(ST, out="{file}"), writes=["{file}"])
robot("robot-stress-out-ro", "robot", "stress", *_flags(ST, out="{ro}"))
robot("robot-stress-out-full", "robot", "stress", *_flags(ST, out="{full}"))  # a folder path that is a device
robot("robot-stress-out-parent-file", "robot", "stress", *_flags(ST, out="{file}/st"), writes=["{file}"])
robot("robot-stress-out-empty", "robot", "stress", *_flags(ST, out=""), writes=["{tmp}/summary.json"])
robot("robot-stress-seed-negative", "robot", "stress", *_flags(ST, seed="-1"), writes=["{tmp}/st"], slow=True)

# ---- vcc bench search / emulator / reproduce / report / learn ---------------------------------
BS = {"concepts": "remove_top_obj", "budget": "1", "width": "1", "out": "{tmp}/bs.json"}
W_BS = ["{tmp}/bs.json"]
case("bench-misses-run-not-a-run", "bench", "misses", "--run", "{dir}", "--out", "{tmp}/m.json", writes=["{tmp}/m.json"])
case("bench-misses-run-missing", "bench", "misses", "--run", "{missing}", "--out", "{tmp}/m.json",
     writes=["{tmp}/m.json"])
BC = {"concepts": "remove_top_obj", "budget": "1", "width": "2", "out": "{tmp}/bc.json"}
case("bench-cluster-workers-zero", "bench", "cluster", *_flags(BC, workers="0"), writes=["{tmp}/bc.json"])
case("bench-cluster-out-dir", "bench", "cluster", *_flags(BC, out="{tmp}/dir.json"), writes=["{tmp}/bc.json"])
case("bench-search-sample-zero", "bench", "search", *_flags(BS, concepts=None, sample="0"), writes=W_BS)
# --sample -1 and --concepts "" would search many concepts: the one-concept --dataset stops them
case("bench-search-sample-negative", "bench", "search", *_flags(BS, concepts=None, sample="-1",
                                                                 dataset="{tmp}/ds/ok"), setup="ds", writes=W_BS)
case("bench-search-concepts-empty", "bench", "search", *_flags(BS, concepts="", dataset="{tmp}/ds/ok"), setup="ds",
     writes=W_BS)
case("bench-search-concepts-commas", "bench", "search", *_flags(BS, concepts=",,"), writes=W_BS)
case("bench-search-concepts-unknown", "bench", "search", *_flags(BS, concepts="bogus"), writes=W_BS)
case("bench-search-model-bad", "bench", "search", *_flags(BS, model="learned"), writes=W_BS)
case("bench-search-budget-zero", "bench", "search", *_flags(BS, budget="0"), writes=W_BS, slow=True)
case("bench-search-budget-negative", "bench", "search", *_flags(BS, budget="-1"), writes=W_BS, slow=True)
case("bench-search-width-zero", "bench", "search", *_flags(BS, width="0"), writes=W_BS, slow=True)
case("bench-search-width-negative", "bench", "search", *_flags(BS, width="-1"), writes=W_BS, slow=True)
case("bench-search-scalar-sample-zero", "bench", "search", *_flags(BS, scalar_sample="0"), writes=W_BS)
case("bench-search-scalar-sample-text", "bench", "search", *_flags(BS, scalar_sample="half"), writes=W_BS,
     slow=True)
for name in ("flipped", "manifest_list", "nan_coords", "shape_index"):
    case(f"bench-search-dataset-{name.replace('_', '-')}", "bench", "search",
         *_flags(BS, dataset=f"{{tmp}}/ds/{name}"), setup="ds", writes=W_BS)
case("bench-search-dataset-missing", "bench", "search", *_flags(BS, dataset="{missing}"), writes=W_BS)
case("bench-search-out-ro", "bench", "search", *_flags(BS, out="{ro}.json"), slow=True)
case("bench-search-out-dir", "bench", "search", *_flags(BS, out="{tmp}/dir.json"), writes=["{tmp}/dir.json"],
     slow=True)
case("bench-search-out-parent-file", "bench", "search", *_flags(BS, out="{file}/bs.json"), writes=["{file}"],
     slow=True)
case("bench-search-out-empty", "bench", "search", *_flags(BS, out=""), slow=True)
BE = {"concepts": "remove_top_obj", "per_concept": "1", "batch": "8", "objects": "2", "raster": "32",
      "repeats": "1", "out": "{tmp}/be.json"}
W_BE = ["{tmp}/be.json"]
for cid, over, slow in [
    ("batch-empty", {"batch": ""}, False), ("batch-text", {"batch": "a"}, False),
    ("batch-commas", {"batch": ",,"}, False),
    ("batch-zero", {"batch": "0"}, True), ("batch-negative", {"batch": "-8"}, True),
    ("batch-huge", {"batch": "1000000000"}, True), ("objects-eleven", {"objects": "11"}, True),
    ("objects-negative", {"objects": "-1"}, True), ("objects-text", {"objects": "two"}, False),
    ("raster-huge", {"raster": "100000"}, True), ("raster-small", {"raster": "8"}, True),
    ("raster-zero", {"raster": "0"}, True), ("raster-text", {"raster": "x"}, False),
    ("repeats-zero", {"repeats": "0"}, True), ("repeats-negative", {"repeats": "-1"}, True),
    ("per-concept-zero", {"per_concept": "0"}, True), ("per-concept-negative", {"per_concept": "-1"}, True),
    ("sample-zero", {"concepts": None, "sample": "0"}, False), ("concepts-unknown", {"concepts": "bogus"}, False),
    ("dataset-flipped", {"dataset": "{tmp}/ds/flipped"}, False), ("out-dir", {"out": "{tmp}/dir.json"}, True),
]:
    case(f"bench-emulator-{cid}", "bench", "emulator", *_flags(BE, **over), writes=W_BE, slow=slow,
         setup="ds" if "dataset" in over else None)
REP = {"runs": "{tmp}/rr", "out": "{tmp}/res/rep.json", "report": "{tmp}/REPORT.md", "others": "", "robot": ""}
W_REP = ["{tmp}/res", "{tmp}/REPORT.md"]
NONE = {"rows": "none"}
for cid, over in [("scale-zero", {"scale": "0"}), ("scale-negative", {"scale": "-1"}), ("scale-nan", {"scale": "nan"}),
                  ("scale-inf", {"scale": "inf"}), ("concepts-empty", {"concepts": ""}),
                  ("concepts-unknown", {"concepts": "bogus"})]:
    case(f"bench-reproduce-{cid}", "bench", "reproduce", *_flags(REP, **NONE, **over), writes=W_REP)
case("bench-reproduce-rows-unknown", "bench", "reproduce", *_flags(REP, rows="o3-magic"), writes=W_REP)
case("bench-reproduce-rows-commas", "bench", "reproduce", *_flags(REP, rows=",,,"), writes=W_REP)
case("bench-reproduce-list-bad-rows", "bench", "reproduce", *_flags(REP, rows="bogus", list=True), writes=W_REP)
case("bench-reproduce-dup-rows", "bench", "reproduce", *_flags(REP, **NONE), "--rows", "none", writes=W_REP)
case("bench-reproduce-workers-without-cluster", "bench", "reproduce", *_flags(REP, **NONE, workers="2"), writes=W_REP)
case("bench-reproduce-workers-zero", "bench", "reproduce", *_flags(REP, **NONE, cluster="ray", workers="0"),
     writes=W_REP)
case("bench-reproduce-cluster-unknown", "bench", "reproduce", *_flags(REP, **NONE, cluster="spark"), writes=W_REP)
ROW = {"rows": "examples-1", "concepts": "remove_top_obj", "scale": "0.000001", "quiet": True}
case("bench-reproduce-width-zero", "bench", "reproduce", *_flags(REP, **ROW, width="0"), writes=W_REP, slow=True)
case("bench-reproduce-dataset-flipped", "bench", "reproduce", *_flags(REP, **ROW, dataset="{tmp}/ds/flipped"),
     setup="ds", writes=W_REP, slow=True)
case("bench-reproduce-dataset-list", "bench", "reproduce", *_flags(REP, **ROW, dataset="{tmp}/ds/manifest_list"),
     setup="ds", writes=W_REP, slow=True)
REPRODUCE_TOO = ("out-ro", "report-dir", "runs-badline", "others-budget", "robot-fields", "results-bad")
for command, extra in (("reproduce", NONE), ("report", {})):
    b = f"bench-{command}"
    first = len(CASES)
    case(f"{b}-out-ro", "bench", command, *_flags(REP, **extra, out="{ro}.json"), writes=W_REP)
    case(f"{b}-out-dir", "bench", command, *_flags(REP, **extra, out="{tmp}/dir.json"),
         writes=["{tmp}/dir.json", "{tmp}/REPORT.md"])
    case(f"{b}-out-parent-file", "bench", command, *_flags(REP, **extra, out="{file}/rep.json"),
         writes=["{file}", "{tmp}/REPORT.md"])
    case(f"{b}-report-dir", "bench", command, *_flags(REP, **extra, report="{tmp}/dir.gif"),
         writes=["{tmp}/res", "{tmp}/dir.gif"])
    case(f"{b}-report-ro", "bench", command, *_flags(REP, **extra, report="{ro}.md"), writes=W_REP)
    case(f"{b}-runs-file", "bench", command, *_flags(REP, **extra, runs="{file}"), writes=W_REP)
    for name in ("runs_list", "runs_badline", "runs_summary_list"):
        case(f"{b}-{name.replace('_', '-')}", "bench", command, *_flags(REP, **extra, runs=f"{{tmp}}/b/{name}"),
             setup="bench", writes=W_REP)
    for name in ("others_budget", "others_meta_list"):
        case(f"{b}-{name.replace('_', '-')}", "bench", command, *_flags(REP, **extra, others=f"{{tmp}}/b/{name}"),
             setup="bench", writes=W_REP)
    for name in ("robot_fields", "robot_types"):
        case(f"{b}-{name.replace('_', '-')}", "bench", command, *_flags(REP, **extra, robot=f"{{tmp}}/b/{name}"),
             setup="bench", writes=W_REP)
    case(f"{b}-results-bad", "bench", command, *_flags(REP, **extra, out="{tmp}/b/results_bad/rep.json"),
         setup="bench", writes=["{tmp}/b/results_bad", "{tmp}/REPORT.md"])
    if command == "reproduce":  # the same report code: a few of its cases are enough here
        CASES[first:] = [c for c in CASES[first:] if c["id"][len(b) + 1:] in REPRODUCE_TOO]
case("bench-report-unknown-flag", "bench", "report", *_flags(REP, rows="none"), writes=W_REP)
BL = {"programs": "{tmp}/p/list_ok.txt", "run": "{tmp}/bl", "out": "{tmp}/bl.json", "budget": "1", "width": "1",
      "quiet": True}
W_BL = ["{tmp}/bl", "{tmp}/bl.json"]
for cid, value in [("zero", "0"), ("eleven", "11"), ("text", "a"), ("empty", "")]:
    case(f"bench-learn-examples-{cid}", "bench", "learn", *_flags(BL, examples=value), setup="progs", writes=W_BL)
for name in ("badline", "binary"):
    case(f"bench-learn-programs-{name.replace('_', '-')}", "bench", "learn",
         *_flags(BL, programs=f"{{tmp}}/p/list_{name}.txt"), setup="progs", writes=W_BL)
case("bench-learn-programs-dir", "bench", "learn", *_flags(BL, programs="{dir}"), writes=W_BL)
case("bench-learn-programs-missing", "bench", "learn", *_flags(BL, programs="{missing}"), writes=W_BL)
case("bench-learn-budget-zero", "bench", "learn", *_flags(BL, budget="0"), setup="progs", writes=W_BL, slow=True)
case("bench-learn-budget-negative", "bench", "learn", *_flags(BL, budget="-1"), setup="progs", writes=W_BL,
     slow=True)
case("bench-learn-ask-zero", "bench", "learn", *_flags(BL, ask_examples="0"), setup="progs", writes=W_BL, slow=True)
case("bench-learn-width-zero", "bench", "learn", *_flags(BL, width="0"), setup="progs", writes=W_BL, slow=True)
case("bench-learn-run-file", "bench", "learn", *_flags(BL, run="{file}"), setup="progs",
     writes=["{file}", "{tmp}/bl.json"])
case("bench-learn-run-ro", "bench", "learn", *_flags(BL, run="{ro}"), setup="progs", writes=["{tmp}/bl.json"])
case("bench-learn-run-other", "bench", "learn", *_flags(BL, run="{tmp}/runs/ok"), setup=["progs", "runs"],
     writes=["{tmp}/runs/ok", "{tmp}/bl.json"], slow=True)
for name in ("foreign", "manifest_list"):
    case(f"bench-learn-dataset-{name.replace('_', '-')}", "bench", "learn",
         *_flags(BL, dataset=f"{{tmp}}/ds/{name}"), setup=["progs", "ds"],
         writes=[f"{{tmp}}/ds/{name}", "{tmp}/bl.json"])
case("learn-filters-bad", "learn", EXOK, *_flags(LE, filters="some"), setup="examples", writes=W_OUT)
