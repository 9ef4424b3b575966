"""Hostile cases for `vcc bench search` / `emulator` / `reproduce` / `report` / `learn`."""

from __future__ import annotations

from tests.vcc.hostile_table import CASES, _flags, case

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
