"""`benchmarks/REPORT.md`, generated from the measured result files only: every table
names the file it came from, and that file's date, commit, machine and command."""

from __future__ import annotations

import json
from pathlib import Path

from vcc import reproduce as rp
from vcc.report_targets import by_date, targets_section
from vccjax.errors import DataFileError, read_json

RULED, RAISED = "the objects acted on rule out", ", those the pairs point in raised"  # `--filters` said


def _load(folder: Path) -> list[tuple[str, dict]]:
    """The result files (JSON objects naming their benchmark) in `folder`; other JSON is
    not ours and is passed over, a file that is not JSON is named in one error line."""
    out = []
    for f in sorted(folder.glob("*.json")):
        d = read_json(f, DataFileError, "missing")
        if isinstance(d, dict) and "benchmark" in d:
            out.append((f.name, d))
    return out


def _stamp(name: str, d: dict) -> str:
    m = d.get("machine", {})
    return (f"`{name}`: {d.get('date', '?')}, commit {d.get('commit', '?')}, {m.get('cores', '?')} cores "
            f"({m.get('cpu', '?')}), JAX {m.get('jax', '?')} on {', '.join(m.get('devices', []))}; "
            f"command `{d.get('command', '?')}`")


def emulator_section(results: list[tuple[str, dict]]) -> list[str]:
    runs = by_date(results, "emulator")
    if not runs:
        return ["## Emulator", "", "Not run (`vcc bench emulator`).", ""]
    lines = ["## Emulator: batched JAX vs the reference interpreter, same stream, same run", ""]
    for name, d in runs:
        lines += [_stamp(name, d), "", f"{d['stream']['programs']} children of a real search "
                  f"({len(d['concepts'])} concepts), each stepped on all its examples.", "",
                  "| setting | JAX programs/s | reference programs/s | ratio | compile s |", "|---|---|---|---|---|"]
        sw = d["sweeps"]
        for label, m in ([(f"batch {m['batch']}", m) for m in sw["batch"]]
                         + [(f"{m['objects']} objects", m) for m in sw["objects"]]
                         + [(f"raster {m['raster']}", m) for m in sw["raster"]]):
            lines.append(f"| {label} | {m['jax_programs_per_second']:,} | {m['reference_programs_per_second']:,} | "
                         f"{m['ratio']} | {m['first_pass_seconds_with_compile']} |")
        per = sorted(d["main"]["per_instruction"].items(), key=lambda x: -x[1]["programs"])
        lines += ["", "Per instruction (main setting): " + ", ".join(
            f"{n} {r['ratio']}x ({r['programs']})" for n, r in per), ""]
    return lines


def search_section(results: list[tuple[str, dict]]) -> list[str]:
    runs = by_date(results, "search")
    if not runs:
        return ["## Search", "", "Not run (`vcc bench search`).", ""]
    lines = ["## Search: batched vs scalar-driven, same concepts, same run", "",
             "Programs searched counts as the paper does (a pruned prefix counts for the programs "
             "under it); programs run are those stepped to the end on all training examples.", "",
             "| file | model | concepts x budget | batched programs searched/s | batched programs run/s | "
             "scalar programs searched/s | ratio | same results |", "|---|---|---|---|---|---|---|---|"]
    for name, d in runs:
        b, s = d["batched"], d["scalar"]
        lines.append(f"| `{name}` | {d['model']} | {len(d['concepts'])} x {d['budget']:,} | "
                     f"{b['programs_per_second']:,} | {round(b['programs_run'] / b['seconds']):,} | "
                     f"{s['programs_per_second']:,} | {d['ratio']} | {d['results_agree']} |")
    lines += [""] + [f"- {_stamp(n, d)}" for n, d in runs] + [""]
    return lines


def _cell(s: dict | None) -> str:
    if s is None:
        return "not run"
    part = "" if s.get("complete") else " (partial: run interrupted, resumable)"
    last = s.get("found_in_last_pass", 0)
    pass_ = (f" ({s['found'] - last} before the last pass, which found {last}, "
             f"{s.get('found_in_parts', 0)} of them in parts)" if last else "")
    return f"{s['found']} of {s['concepts']}{pass_}{part}"


def _pass(settings: dict) -> str:
    """The last pass after the iterations, where a run's settings have one."""
    return (f", then a last pass (whole, then in up to {settings['parts']} parts)"
            if settings.get("parts", 1) > 1 else "")


def _predicted(settings: dict) -> str:
    """With predicted arguments: a threshold other than the paper's 0.55, and fill_color's
    arguments from the colours objects gain (`--fill gained`; folders written before
    `fill` existed took them from the network), filter values the objects acted on rule
    out dropped (`--filters acted`; before `filters`: the network's alone)."""
    if not str(settings.get("args", "")).startswith("predicted"):
        return ""
    t = settings.get("arg_threshold", 0.55)
    return ((f", threshold {t:g}" if t != 0.55 else "")
            + (", fill_color from the colours objects gain" if settings.get("fill") == "gained" else "")
            + (f", filters {RULED} dropped" if str(settings.get("filters")).startswith("acted") else "")
            + (RAISED if settings.get("filters") == "acted+raised" else ""))


def _weights(s: dict | None) -> str:
    """Which argument-predictor weights a run used, where its run.json says."""
    return f" (predictor `{s['predictor_sha256'][:8]}`)" if s and s.get("predictor_sha256") else ""


def reproduce_section(rows: dict[str, dict]) -> list[str]:
    lines = ["## The paper's experiments (`vcc bench reproduce`)", "",
             "Each row is an explore-compress run of ours (`search.induce`) beside the paper's figure. "
             "A row not run says so; a partial one is a run that was interrupted and resumes where it "
             "stopped. Rows on fewer concepts or a scaled budget say so in their folder name.", "",
             "| row | setting | paper | ours: induced | without subroutines | exact on all 50 test pairs | "
             "wall | folder |", "|---|---|---|---|---|---|---|---|"]
    for row in rp.ROWS:
        if row.short_only:
            continue
        for key, s in _row_runs(rows, row.name) or [(row.name, None)]:
            lines.append(
                f"| {row.name} | {row.what}{_predicted(st := (s or {}).get('settings', {}))}{_pass(st)}{_weights(s)} | "
                f"{row.paper} | {_cell(s)} | "
                + (f"{s['found_without_subroutines']} | {s['exact_on_all_test_pairs']} | "
                   f"{s['wall_seconds'] / 60:.0f} min | `{key}` |" if s else "- | - | - | - |"))
    curve = [(row, _row_runs(rows, row.name)) for row in rp.ROWS if row.short_only]
    lines += ["", f"### Learning curve: concepts correct vs training examples (concepts whose reference "
              f"program has at most {rp.SHORT} instructions; iteration 0 only)", "",
              "Paper: most concepts learned from a few examples; the curve flattens after 5 (Fig 5C).", "",
              "| examples | induced | exact on all 50 test pairs | folder |", "|---|---|---|---|"]
    for row, runs in curve:
        for key, s in runs or [(row.name, None)]:
            lines.append(f"| {row.examples} | {_cell(s)} | {s['exact_on_all_test_pairs'] if s else '-'} | "
                         + (f"`{key}` |" if s else "- |"))
    main = _row_runs(rows, rp.MAIN)
    if main:
        key, s = main[0]
        lines += ["", f"### Per iteration ({key}): new concepts and their program lengths", "",
                  "| iteration | new concepts | lengths (instructions: programs) |", "|---|---|---|"]
        for it, n in s["per_iteration"].items():
            ls = s.get("lengths_per_iteration", {}).get(str(it), {})
            lines.append(f"| {it} | {n} | " + ", ".join(f"{k}: {v}" for k, v in ls.items()) + " |")
    return lines + [""]


def _row_runs(rows: dict[str, dict], name: str) -> list[tuple[str, dict]]:
    """Run folders of one row: the full run first, then samples or scaled budgets."""
    got = [(k, s) for k, s in rows.items() if s.get("row") == name]
    return sorted(got, key=lambda x: (x[0] != name, x[0]))


def other_runs_section(folder: Path) -> list[str]:
    """Induction runs committed elsewhere (the run of record, the argument ablation): their
    settings differ from the paper's rows, so they stand apart."""
    found = sorted(p.parent for p in folder.rglob("run.json")) if folder.exists() else []
    if not found:
        return []
    lines = [f"## Other induction runs (`{folder}`)", "",
             "| folder | settings | induced | without subroutines | exact on all 50 test pairs | wall | "
             "programs/s searched (run on all examples) |", "|---|---|---|---|---|---|---|"]
    for path in found:
        s = rp.read_row(path)
        st = json.loads((path / "run.json").read_text()).get("settings", {})
        if s is None:
            continue
        lines.append(f"| `{path}` | order {st.get('order')}, {st.get('args')} arguments, budget {st.get('budget'):,}, "
                     f"subroutines {'on' if st.get('subroutines') else 'off'}{_predicted(st)}{_pass(st)}{_weights(s)} | "
                     f"{_cell(s)} | "
                     f"{s['found_without_subroutines']} | {s['exact_on_all_test_pairs']} | "
                     f"{s['wall_seconds'] / 60:.0f} min | {s['programs_per_second']:,} "
                     f"({s['programs_run_per_second']:,}) |")
    return lines + [""]


def robot_section(folder: Path) -> list[str]:
    """Every arm suite under `folder` (a summary.json written by `vcc robot suite`):
    successes, failures by cause and the camera's parse against the true tables."""
    found = []
    for path in sorted(folder.glob("*/summary.json")) if folder.exists() else []:
        try:
            s = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError):
            continue
        if isinstance(s, dict) and "source" in s and "parse" in s:
            found.append((path.parent, s))
    if not found:
        return []
    lines = [f"## The arm (`{folder}`, `vcc robot suite`)", "",
             "| folder | programs | concepts recorded | scenarios each | carried out | failures by cause | "
             "objects parsed exact |", "|---|---|---|---|---|---|---|"]
    for path, s in found:
        src = s["source"]
        where = f"{src['kind']} `{src['path']}`" if src.get("path") else src["kind"]
        fails = ", ".join(f"{c} {n}" for c, n in sorted(s["failures"].items(), key=lambda x: -x[1])) or "none"
        p = s["parse"]
        lines.append(f"| `{path}` | {where} | {s['concepts']} of {s['of']} | {s['scenarios']} | "
                     f"{s['success']} of {s['rollouts']} ({s['success'] / max(1, s['rollouts']):.1%}) | {fails} | "
                     f"{p['objects_exact']} of {p['objects']} ({p['objects_exact'] / max(1, p['objects']):.2%}) |")
    return lines + [""]


def stress_section(folder: Path) -> list[str]:
    """Every stress run under `folder` (a summary.json written by `vcc robot stress`):
    rollouts, non-finite states, and what was not carried out, by cause."""
    found = []
    for path in sorted(folder.glob("*/summary.json")) if folder.exists() else []:
        try:
            s = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError):
            continue
        if isinstance(s, dict) and "non_finite" in s and "rollouts" in s:
            found.append((path.parent, s))
    if not found:
        return []
    lines = [f"## The arm's stress runs (`{folder}`, `vcc robot stress`)", "",
             "| folder | rollouts | concepts drawn | rolled out | non-finite states | carried out | failures by cause |",
             "|---|---|---|---|---|---|---|"]
    for path, s in found:
        fails = ", ".join(f"{c} {n}" for c, n in sorted(s["failures"].items(), key=lambda x: -x[1])) or "none"
        lines.append(f"| `{path}` | {s['rollouts']} | {s['concepts']} | {s['rolled_out']} | {s['non_finite']} | "
                     f"{s['success']} ({s['success'] / max(1, s['rollouts']):.1%}) | {fails} |")
    return lines + [""]


def cluster_section(results: list[tuple[str, dict]]) -> list[str]:
    """One process against Ray workers on the same search (`vcc bench cluster`)."""
    runs = by_date(results, "cluster")
    if not runs:
        return []
    lines = ["## Explore-compress on Ray workers (`vcc bench cluster`)", "",
             "| file | model | concepts x budget | one process s | workers | workers s | speed-up | same results |",
             "|---|---|---|---|---|---|---|---|"]
    for name, d in runs:
        lines.append(f"| `{name}` | {d['model']} | {len(d['concepts'])} x {d['budget']:,} | {d['single']['seconds']} | "
                     f"{d['cluster']['workers']} | {d['cluster']['seconds']} | {d['speedup']}x | {d['results_agree']} |")
    return lines + ["", "Second passes timed (the first compiles). The one process uses both cores, each "
                    "worker one (docs/cluster.md).", ""] + [f"- {_stamp(name, d)}" for name, d in runs] + [""]


def camera_section(results: list[tuple[str, dict]]) -> list[str]:
    """The arm camera's parse against the true tables (`vcc robot perception`), per condition."""
    runs = by_date(results, "robot-perception")
    if not runs:
        return []
    name, d = runs[-1]
    lines = ["## The arm's camera: parse against the true tables", "", _stamp(name, d), "",
             "| condition | objects exact | scenes exact | largest centre error |", "|---|---|---|---|"]
    for cond, t in d["conditions"].items():
        lines.append(f"| {cond} | {t['objects_exact']} of {t['objects']} ({t['objects_exact'] / max(1, t['objects']):.2%})"
                     f" | {t['scenes_exact']} of {t['scenes']} | {t['largest_centre_error_m'] * 1000:.1f} mm |")
    return lines + [""]


def learn_section(results: list[tuple[str, dict]]) -> list[str]:
    """New concepts learned from their pairs (`vcc bench learn`): the library against from
    scratch, the questions asked back, and `vcc learn`'s wall time cold and warm."""
    runs = by_date(results, "learn")
    if not runs:
        return []
    name, d = runs[-1]
    lines = [f"## New concepts learned from their pairs ({d['concepts']}, none among the 546)", "", _stamp(name, d), "",
             "| start, examples | found | right on all test pairs | of them learned in parts |", "|---|---|---|---|"]
    for label, row in d["learn"].items():
        lines.append(f"| {label} | {row['found']} of {row['concepts']} | {row['right']} of {row['concepts']} | "
                     f"{row.get('right_in_parts', 'not counted')} |")
    a = d["ask"]
    lines += ["", f"Asking back from {a['examples']} examples: first program right {a['first_right']}, wrong "
              f"{a['first_wrong']}; of the wrong, reported ambiguous {a['wrong_reported_ambiguous']}, settled by one "
              f"answered query {a['wrong_settled_by_one_query']}; right but reported ambiguous "
              f"{a['right_reported_ambiguous']}."]
    t = d.get("timing")
    if t:
        lines += ["", f"`vcc learn` on `{t['concept']}` ({t['instructions']} instructions, {t['pairs']} JSON pairs), "
                      f"a fresh process each: cold {t['cold_seconds']} s, warm {t['warm_seconds']} s on "
                      f"{t['cores']} cores."]
    return lines + [""]


MISSES_SHOWN = 8  # concepts a predictor misses, named in its row (the file lists them all)


def argpred_section(results: list[tuple[str, dict]]) -> list[str]:
    """The argument predictor's recall and sharpness (`vcc argpred eval`): concepts whose
    used arguments all pass the threshold, and the arguments passed that a concept never
    uses, per function (each widens the search)."""
    runs = by_date(results, "argpred-recall")
    if not runs:
        return []
    lines = ["## Argument predictor: recall and extra arguments (`vcc argpred eval`)", "",
             "| file | weights | fill_color from | filters | concepts (split) | threshold | recalled: every used argument "
             "passes | mean extra arguments per concept, by function | not recalled |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name, d in runs:
        n = d["concepts"] if isinstance(d["concepts"], int) else len(d["concepts"])
        extra = ", ".join(f"{f} {v:.2f}" for f, v in d["mean_extra_arguments"].items())
        shown = list(d["missed"].items())[:MISSES_SHOWN]
        missed = "; ".join(f"{c}: " + ", ".join(f"{f}({', '.join(v)})" for f, v in fs.items())
                           for c, fs in shown) or "none"
        if len(d["missed"]) > len(shown):
            missed += f"; and {len(d['missed']) - len(shown)} more (in the file)"
        fill = "the gained colours" if d.get("fill") == "gained" else "the network"  # files before `fill`: the network
        filters = (f"less those {RULED}" + (RAISED if d.get("filters") == "acted+raised" else "")
                   if str(d.get("filters")).startswith("acted") else "the network")
        lines.append(f"| `{name}` | {d['weights']} `{d['weights_sha256'][:8]}` ({d['members']} networks) | {fill} | "
                     f"{filters} | "
                     f"{n} ({d['split']}) | {d.get('threshold', 0.55):g} | {d['recalled']} ({d['recall']:.1%}) | {extra} | "
                     f"{missed} |")
    return lines + [""] + [f"- `{n}`: {d.get('date', '?')}, commit {d.get('commit', '?')}; command "
                           f"`{d.get('command', '?')}`" for n, d in runs] + [""]


def collect_rows(runs: Path) -> dict[str, dict]:
    """Every row folder under `runs` that holds a run, by folder name."""
    out = {}
    if runs.exists():
        for path in sorted(p for p in runs.iterdir() if p.is_dir()):
            try:
                s = rp.read_row(path)
            except DataFileError:
                raise
            except (TypeError, AttributeError, KeyError, IndexError, ValueError) as e:
                raise DataFileError(f"{path}: not a run the report can read ({type(e).__name__}: "
                                    f"{str(e)[:80]})") from None
            if s is not None:
                out[path.name] = s
    return out


def render(results_dir: Path, rows: dict[str, dict], stamp: dict, others: Path | None = None,
           robot: Path | None = None, runs: Path | None = None, compiled: Path | None = None) -> str:
    """The report's text; a result file, row or run of the wrong shape is named in one
    error line (nothing is written before the whole text is made)."""
    results = _load(results_dir)
    lines = ["# vccjax benchmark report", "",
             f"Generated {stamp['date']} at commit {stamp['commit']} by `{stamp['command']}` on "
             f"{stamp['machine']['cores']} cores ({stamp['machine']['cpu']}), JAX {stamp['machine']['jax']}. "
             f"Only measured numbers: each table names its result file or run folder.", ""]
    for section, source in ((lambda: targets_section(results, rows, others, compiled),
                             f"{results_dir}, {runs}, {others} or {compiled}"),
                            (lambda: emulator_section(results), results_dir),
                            (lambda: search_section(results), results_dir),
                            (lambda: reproduce_section(rows), runs),
                            (lambda: other_runs_section(others) if others else [], others),
                            (lambda: robot_section(robot) if robot else [], robot),
                            (lambda: stress_section(robot) if robot else [], robot),
                            (lambda: camera_section(results), results_dir),
                            (lambda: learn_section(results), results_dir),
                            (lambda: argpred_section(results), results_dir),
                            (lambda: cluster_section(results), results_dir)):
        try:
            lines += section()
        except DataFileError:
            raise
        except (TypeError, AttributeError, KeyError, IndexError, ValueError) as e:
            raise DataFileError(f"{source}: a result there is not of the shape the report reads "
                                f"({type(e).__name__}: {str(e)[:80]})") from None
    return "\n".join(lines)

