"""Hostile cases for the searching commands: `vcc induce`, `vcc learn` and
`vcc library build` / `show`."""

from __future__ import annotations

from tests.vcc.hostile_table import _flags, case

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
