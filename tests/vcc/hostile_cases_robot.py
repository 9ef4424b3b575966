"""Hostile cases for `vcc robot run` / `suite` / `perception` / `stress`."""

from __future__ import annotations

from tests.vcc.hostile_table import NO_DEVICE, _flags, case

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
