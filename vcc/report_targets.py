"""The report's targets table: each acceptance line beside the figure a committed result
file or run folder holds, and whether it is met. A line with nothing measured says so;
none is judged from anything but those files."""

from __future__ import annotations

from pathlib import Path

from vcc import reproduce as rp
from vccjax.errors import DataFileError, read_json

# the first specification's targets, then those of the speed and paper-setting work
TARGETS = {"emulator": 20.0, "search": 25_000, "main_wall_s": 2 * 3600, "main_found": 540,
           "instruction": 5.0, "instruction_programs": 100, "raster": 128, "raster_ratio": 10.0,
           "library_run": 50_000, "library_ratio": 20.0, "library_budget": 500_000, "library_concepts": 64,
           "oracle_wall_s": 3600, "compile_s": 15.0, "main_exact": 538, "long_row": "o1-predfix-3M",
           "long_found": 544}


def _yes(ok: bool) -> str:
    return "yes" if ok else "no"


def by_date(results: list[tuple[str, dict]], kind: str) -> list[tuple[str, dict]]:
    """The result files of one benchmark, oldest first (the report's tables read them too)."""
    return sorted([r for r in results if r[1]["benchmark"] == kind], key=lambda r: r[1].get("date", ""))


def emulator_lines(results: list[tuple[str, dict]]) -> list[str]:
    """The latest emulator file: its main ratio, its slowest common instruction and its
    finest raster."""
    emu = by_date(results, "emulator")
    if not emu:
        return ["| JAX emulator >= 20x | not run | - |"]
    name, d = emu[-1]
    r = d["main"]["ratio"]
    lines = [f"| JAX emulator >= {TARGETS['emulator']:.0f}x the reference, mixed stream | {r}x "
             f"(`{name}`) | {_yes(r >= TARGETS['emulator'])} |"]
    many = {op: v for op, v in d["main"].get("per_instruction", {}).items()
            if v["programs"] >= TARGETS["instruction_programs"]}
    if many:
        op = min(many, key=lambda o: many[o]["ratio"])
        lines.append(f"| no instruction with {TARGETS['instruction_programs']} or more programs in that stream "
                     f"below {TARGETS['instruction']:.0f}x | slowest: `{op}` {many[op]['ratio']}x "
                     f"({many[op]['programs']} programs) | {_yes(many[op]['ratio'] >= TARGETS['instruction'])} |")
    raster = [s for s in d.get("sweeps", {}).get("raster", []) if s.get("raster") == TARGETS["raster"]]
    if raster:
        lines.append(f"| raster {TARGETS['raster']}: >= {TARGETS['raster_ratio']:.0f}x | {raster[0]['ratio']}x | "
                     f"{_yes(raster[0]['ratio'] >= TARGETS['raster_ratio'])} |")
    return lines


def _one_device(d: dict) -> bool:
    return len(d.get("machine", {}).get("devices", [])) <= 1


def search_lines(results: list[tuple[str, dict]]) -> list[str]:
    """The first specification's line (the best run-to-the-end rate of any search file),
    then the learned library's benchmark: judged on its latest one-device file, the
    default setting; the best of any file and setting named beside it."""
    srch = by_date(results, "search")
    if not srch:
        return ["| search >= 25,000 programs/s | not run | - |"]
    best = max(srch, key=lambda x: x[1]["batched"]["programs_run"] / x[1]["batched"]["seconds"])
    b = best[1]["batched"]
    run_rate = round(b["programs_run"] / b["seconds"])
    lines = [f"| search >= 25,000 programs/s, each on all 10 training examples | {run_rate:,} run to the "
             f"end on all examples; {b['programs_per_second']:,} searched as the paper counts (`{best[0]}`) | "
             f"{_yes(run_rate >= TARGETS['search'])} (run to the end); "
             f"{_yes(b['programs_per_second'] >= TARGETS['search'])} (paper's count) |"]
    lib = [(n, d) for n, d in srch if d.get("model") == "library" and d.get("budget") == TARGETS["library_budget"]
           and len(d.get("concepts", [])) == TARGETS["library_concepts"]]
    what = (f"search on the learned library, {TARGETS['library_concepts']} concepts x "
            f"{TARGETS['library_budget']:,}: >= {TARGETS['library_run']:,} programs/s run to the end on all "
            f"examples, >= {TARGETS['library_ratio']:.0f}x the scalar-driven search, same results")
    default = [x for x in lib if _one_device(x[1])]
    if not default:
        return lines + [f"| {what} | not run on one device | - |"]
    name, d = default[-1]

    def rate(x: dict) -> int:
        return round(x["batched"]["programs_run"] / x["batched"]["seconds"])

    fast, wide = max(lib, key=lambda x: rate(x[1])), max(lib, key=lambda x: x[1]["ratio"])
    ok = rate(d) >= TARGETS["library_run"] and d["ratio"] >= TARGETS["library_ratio"] and d["results_agree"]
    lines.append(f"| {what} | {rate(d):,}/s, {d['ratio']}x, results {'agree' if d['results_agree'] else 'differ'} "
                 f"(`{name}`, one device); best of any setting: {rate(fast[1]):,}/s (`{fast[0]}`), "
                 f"{wide[1]['ratio']}x (`{wide[0]}`) | {_yes(ok)} |")
    return lines


def _runs(folder: Path | None) -> list[tuple[Path, dict, dict]]:
    """(folder, run.json, summary.json) of every finished run under `folder` (none when
    it does not exist; a file there, or a run file we cannot read, is named in one line)."""
    if folder is None or not folder.exists():
        return []
    if not folder.is_dir():
        raise DataFileError(f"{folder}: not a folder of run folders")
    out = []
    for run in sorted(folder.rglob("run.json")):
        summary = run.parent / "summary.json"
        if summary.exists():
            meta, s = (read_json(f, DataFileError, "missing") for f in (run, summary))
            if not isinstance(meta, dict) or not isinstance(s, dict):
                raise DataFileError(f"{run.parent}: run.json and summary.json must hold objects")
            out.append((run.parent, meta, s))
    return out


def oracle_line(others: Path | None) -> str:
    """The 546 at 0.5M, order 1, oracle arguments: the fastest such run against the
    first (the run of record) for the concepts found."""
    what = f"the 546 at 0.5M, order 1, oracle arguments: <= {TARGETS['oracle_wall_s'] // 60} min wall, as many found"
    runs = [(p, m, s) for p, m, s in _runs(others)
            if s["concepts"] == 546 and m["settings"].get("args") == "oracle" and m["settings"].get("order") == 1
            and m["settings"].get("budget") == 500_000]
    if not runs:
        return f"| {what} | not run | - |"
    record = min(runs, key=lambda r: min(r[1].get("sessions") or [0]))
    p, _, s = min(runs, key=lambda r: r[2]["wall_seconds"])
    ok = s["wall_seconds"] <= TARGETS["oracle_wall_s"] and s["found"] >= record[2]["found"]
    return (f"| {what} as the run of record (`{record[0]}`: {record[2]['found']}) | {s['found']} in "
            f"{s['wall_seconds'] / 60:.0f} min (`{p}`) | {_yes(ok)} |")


def compile_line(folder: Path | None) -> str:
    """A fresh `vcc induce` on the demo set with an empty compile cache: its latest run."""
    what = f"compile time of a fresh `vcc induce` on the demo set, cold cache: <= {TARGETS['compile_s']:.0f} s"
    runs = _runs(folder)
    if not runs:
        return f"| {what} | not run | - |"
    p, _, s = max(runs, key=lambda r: max(r[1].get("sessions") or [0]))
    return (f"| {what} | {s['compile_seconds']:.1f} s of a {s['wall_seconds']:.1f} s run (`{p}`) | "
            f"{_yes(s['compile_seconds'] <= TARGETS['compile_s'])} |")


def row_lines(rows: dict[str, dict]) -> list[str]:
    """The paper-setting headline row, the long row, and every row run to the end."""
    lines = []
    main = rows.get(rp.MAIN)
    what = (f"all 546, order 1, predicted + fixation, 0.5M: <= {TARGETS['main_wall_s'] // 3600} h, >= "
            f"{TARGETS['main_found']} found (the paper: 526), right on all 50 test pairs for >= "
            f"{TARGETS['main_exact']}")
    if main and main.get("complete"):
        ok = (main["found"] >= TARGETS["main_found"] and main["exact_on_all_test_pairs"] >= TARGETS["main_exact"]
              and main["wall_seconds"] <= TARGETS["main_wall_s"])
        lines.append(f"| {what} | {main['found']} ({main['exact_on_all_test_pairs']} right on all 50) in "
                     f"{main['wall_seconds'] / 3600:.2f} h | {_yes(ok)} |")
    else:
        lines.append(f"| {what} | {'partial' if main else 'not run'} | - |")
    long = rows.get(TARGETS["long_row"])
    what = f"the {TARGETS['long_row']} row: >= {TARGETS['long_found']}"
    if long:
        ok = bool(long.get("complete")) and long["found"] >= TARGETS["long_found"]
        lines.append(f"| {what} | {long['found']}{'' if long.get('complete') else ' (partial)'} | {_yes(ok)} |")
    else:
        lines.append(f"| {what} | not run | - |")
    listed = [r.name for r in rp.ROWS]
    done = [n for n in listed if rows.get(n, {}).get("complete")]
    lines.append(f"| every row of `vcc bench reproduce --list` run to the end | {len(done)} of {len(listed)} | "
                 f"{_yes(len(done) == len(listed))} |")
    return lines


def targets_section(results: list[tuple[str, dict]], rows: dict[str, dict], others: Path | None = None,
                    compiled: Path | None = None) -> list[str]:
    lines = ["## Targets (this 2-core CPU)", "", "| target | measured | met |", "|---|---|---|"]
    lines += emulator_lines(results) + search_lines(results)
    lines += [oracle_line(others), compile_line(compiled)] + row_lines(rows)
    return lines + [""]
