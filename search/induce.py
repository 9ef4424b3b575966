"""Explore-compress over many concepts, persisted after every concept and resumable.

Iteration 0 searches with a uniform model over the atoms (honest brute force).
After each iteration the model is refitted on every program found so far; with
subroutines on, they stay off until an iteration finds nothing new (saturation), then
compression adds them (as the paper). The run stops when an iteration with its full
model finds nothing new, or after `max_iterations`.

Reference programs are read only to make examples and, for `--args oracle` and the
teacher's fixation guidance, for their arguments.

Files under `out/`: `run.json` (the settings and each concept's examples hash; a
resume must match them), `results.jsonl` (one line per concept tried per iteration,
written as soon as it is known), `model-K.json` (the model searched with in iteration K).
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from argpred.acted import check_filters
from argpred.gained import FILL_MODES
from search.arguments import MODES as ARG_MODES
from search.chain import Chain
from search.explore import Explorer, Searcher
from search.model import MarkovModel, Vocabulary
from search.result import Result
from search.task import Task
from vccjax import files
from vccjax.errors import DataFileError, read_json
from vccjax.machine.config import DEFAULT_CONFIG
from vccjax.machine.program import Program, parse
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, scenes_match
from vccjax.records import Schema, append_line, check_fields, drop_cut_tail, read_jsonl
from vccjax.world.concepts import reference_program


@dataclasses.dataclass(frozen=True)
class Settings:
    budget: int = 500_000
    order: int = 1
    args: str = "predicted"
    subroutines: bool = True
    epsilon: float = 0.1
    max_iterations: int = 8
    max_subroutines: int = 100
    delta: float = 0.01  # nats per cost bin
    parts: int = 1  # >= 2: a last pass over missed concepts, whole then in up to this many parts (1: none)
    arg_threshold: float = 0.55  # predicted arguments pass at this probability (the paper's 0.55)
    fill: str = "gained"  # predicted modes: fill_color's arguments from the colours objects gain, or "predicted"
    filters: str = "acted+raised"  # predicted: filter values the pairs rule out dropped, point in raised

    def __post_init__(self) -> None:
        if self.args not in ARG_MODES:
            raise ValueError(f"--args must be one of {', '.join(ARG_MODES)}, got {self.args!r}")
        if self.order not in (0, 1):
            raise ValueError(f"--order must be 0 or 1, got {self.order}")
        if self.budget < 1:
            raise ValueError("--budget must be positive")
        if not 1 <= self.parts <= 3:
            raise ValueError(f"--parts must be 1, 2 or 3, got {self.parts}")
        if not 0 < self.arg_threshold <= 1:
            raise ValueError(f"--arg-threshold must be above 0 and at most 1, got {self.arg_threshold}")
        if self.fill not in FILL_MODES:
            raise ValueError(f"--fill must be one of {', '.join(FILL_MODES)}, got {self.fill!r}")
        check_filters(self.filters)


def needs_answer(settings: Settings) -> bool:
    """Whether the settings read the concept's answer program (research settings only)."""
    return settings.args == "oracle" or settings.args.endswith("+fixation")


def argument_logp(settings: Settings, concept: str, pairs: Sequence[tuple[Scene, Scene]] | None = None,
                  answer: Program | None = None) -> dict[int, np.ndarray]:
    """log p(argument | instruction) for one concept under the settings' mode
    (`search.arguments`); oracle and +fixation read `answer`, by default the concept's
    reference program when it is one of the 546."""
    from search.arguments import argument_logp as logp

    if answer is None and needs_answer(settings):
        answer = reference_program(concept)
    return logp(settings.args, pairs, answer, threshold=settings.arg_threshold, fill=settings.fill,
                filters=settings.filters)


def fit_model(programs: Sequence[Program], settings: Settings, with_subroutines: bool):
    """The (vocabulary, Markov model) compression gives for the programs found so far."""
    from search.library import fit

    if not programs:
        return Vocabulary(), MarkovModel.uniform(Vocabulary().size, settings.order)
    vocab, counts = fit([p.ops for p in programs], settings.order, settings.epsilon, settings.max_subroutines,
                        with_subroutines)
    return vocab, MarkovModel.from_counts(counts, settings.order, settings.epsilon)


def generalization(program: Program, pairs: Sequence[tuple[Scene, Scene]], tau: float) -> int:
    """How many pairs the program gets right (docs/vcc.md section 7)."""
    good = 0
    for a, b in pairs:
        m = RefMachine(a).run(program)
        good += (not m.failed) and scenes_match(m.output_scene(), b, tau)
    return good


class Run:
    """One induction run on disk."""

    def __init__(self, out: str | Path, settings: Settings):
        self.out = Path(out)
        self.settings = settings
        files.check_writable(self.out, "run", folder=True)
        files.hold(self.out)  # one writer per run folder
        meta = self.out / "run.json"
        mine = dataclasses.asdict(settings)
        self.results_path = self.out / "results.jsonl"
        # everything is read and checked before anything is written: a refused resume
        # leaves the folder as it was
        if meta.exists():
            info = self._meta()
            if not same_search(info.get("settings"), mine):
                old = info.get("settings") if isinstance(info.get("settings"), dict) else {}
                differ = ", ".join(f"{k} {old.get(k)!r} (now {mine.get(k)!r})" for k in sorted(set(old) | set(mine))
                                   if k != "parts" and old.get(k) != mine.get(k))
                raise DataFileError(f"{meta}: this folder holds a run with other settings ({differ or old}); "
                                    "use another --out or the same settings to resume")
        elif self.out.is_dir() and any(not f.name.startswith(".") for f in self.out.iterdir()):
            raise DataFileError(f"{self.out}: holds files but no run.json, so it is not a run to resume; "
                                "use another --out")
        else:
            info = {"format": "vccjax-induce", "version": 1, "settings": mine, "sessions": []}
            self._write_meta(info)
        self.records = read_records(self.results_path)
        # this session's start, for the wall time: written with its first record, so that
        # a resume the checks below refuse (examples, weights, start model) or that has
        # nothing left to do leaves run.json as it was
        self._start: float | None = round(time.time(), 3)
        self.session = len(info.get("sessions", []))

    def _meta(self) -> dict:
        """run.json, checked: an object of this format with its settings and sessions."""
        meta = self.out / "run.json"
        info = read_json(meta, DataFileError, "no run.json in this run folder")
        if not isinstance(info, dict) or info.get("format") != "vccjax-induce":
            raise DataFileError(f"{meta}: not a vccjax induction run's run.json")
        return check_fields(info, {"settings": (dict,), "sessions": (list,)}, str(meta))

    @classmethod
    def view(cls, out: str | Path) -> Run:
        """A run folder read as it is (another process may be writing it): no session is
        recorded and nothing is rewritten."""
        run = cls.__new__(cls)
        run.out, run.results_path = Path(out), Path(out) / "results.jsonl"
        run.settings = None
        run.records = read_records(run.results_path)
        return run

    def check_examples(self, hashes: dict[str, str]) -> None:
        """Record each concept's examples hash; refuse a resume on other examples (a
        rebuilt or different dataset would mix two runs in one results file)."""
        meta = self.out / "run.json"
        info = self._meta()
        known = info.setdefault("examples_sha256", {})
        changed = sorted(c for c, h in hashes.items() if known.get(c, h) != h)
        if changed:
            raise DataFileError(
                f"{meta}: this run searched other examples for {', '.join(changed[:3])}"
                + (f" and {len(changed) - 3} more" if len(changed) > 3 else "")
                + "; use the dataset it was started with, or another --out"
            )
        if any(c not in known for c in hashes):
            known.update(hashes)
            self._write_meta(info)

    def check_predictor(self, sha256: str) -> None:
        """Record the argument predictor's weights (sha256); refuse a resume under other
        weights, or of records whose weights were not recorded (they would mix)."""
        meta = self.out / "run.json"
        info = self._meta()
        known = info.get("predictor_sha256")
        if known is None and self.records:
            raise DataFileError(f"{meta}: this run's records do not say which argument-predictor weights made "
                                "them; use another --out to run with these")
        if known is not None and known != sha256:
            raise DataFileError(f"{meta}: this run used other argument-predictor weights (sha256 {known[:12]}..., "
                                f"these are {sha256[:12]}...); use another --out, or those weights")
        if known is None:
            info["predictor_sha256"] = sha256
            self._write_meta(info)

    def check_start(self, name: str) -> None:
        """Record the model the run started from ('uniform' or a learned model's hash);
        refuse a resume from another (its records would mix two starts)."""
        meta = self.out / "run.json"
        info = self._meta()
        known = info.get("start_model", "uniform")
        if self.records and known != name:
            raise DataFileError(f"{meta}: this run started from model {known[:12]}, not {name[:12]}; "
                                "use another --out or the same --model")
        if info.get("start_model") != name:
            info["start_model"] = name
            self._write_meta(info)

    def _write_meta(self, info: dict) -> None:
        files.write_json(self.out / "run.json", info)  # whole or not at all, if killed while writing

    def found(self) -> dict[str, dict]:
        return {r["concept"]: r for r in self.records if r["found"]}

    def tried(self, iteration: int) -> set[str]:
        return {r["concept"] for r in self.records if r["iteration"] == iteration}

    def append(self, record: dict) -> None:
        if self._start is not None:  # the session's first record: its start and settings first
            info = self._meta()
            info["settings"] = dataclasses.asdict(self.settings)  # a resume may add the parts pass
            info["sessions"].append(self._start)
            self._write_meta(info)
            drop_cut_tail(self.results_path)  # never a rewrite: a kill then would lose the run
            self._start = None
        record = {**record, "session": self.session, "at": round(time.time(), 3)}
        self.records.append(record)
        append_line(self.results_path, record)


def same_search(recorded: object, mine: dict) -> bool:
    """Whether a run folder's recorded settings search as `mine`: all alike but `parts`,
    which only adds a pass after the iterations (a folder written before it existed
    holds none), so a finished run may be resumed to add it. A folder written before
    `arg_threshold` existed searched at 0.55, one written before `fill` took fill_color's
    arguments from the network, one written before `filters` the network's filters;
    `fill` and `filters` matter only to predicted arguments."""
    if not isinstance(recorded, dict):
        return False
    a = {"arg_threshold": 0.55, "fill": "predicted", "filters": "network", **recorded, "parts": 0}
    b = {**mine, "parts": 0}
    if not str(b.get("args", "")).startswith("predicted"):
        for k in ("fill", "filters"):
            a.pop(k), b.pop(k, None)
    return a == b


def read_records(path: Path) -> list[dict]:
    """A results file's records; a last line cut by an interrupt is dropped (that concept
    is redone), any other bad line is an error."""
    records = read_jsonl(path, RECORD_SCHEMA)
    for i, r in enumerate(records):
        if r["found"] and r["program"] is None:
            raise DataFileError(f"{path}: line {i + 1}: a record found has no program")
    return records


# What every results line must hold (more fields are kept as they are).
RECORD_SCHEMA: Schema = {
    "concept": (str,), "found": (bool,), "iteration": (int,), "program": (str, None),
    "dl?": (float, None), "nodes?": (int,), "programs_run?": (int,), "seconds?": (float,),
}


def record_of(concept: str, it: int, r: Result, test: tuple[int, int] | None) -> dict:
    return {
        "concept": concept, "found": r.found, "iteration": it,
        "program": r.program.text() if r.program else None, "compressed": r.text,
        "dl": r.dl_nats, "rank": r.rank, "nodes": r.nodes, "programs_run": r.programs,
        "covered": r.rank if r.found else r.budget, "seconds": round(r.seconds, 3),
        "compile_seconds": round(r.compile_seconds, 3),
        "test_correct": test[0] if test else None, "test_total": test[1] if test else None,
    }


def induce(
    concepts: Sequence[str], pairs: Callable[[str, str], list[tuple[Scene, Scene]]],
    out: str | Path, settings: Settings, explorer: Searcher | None = None,
    progress: bool = True, log: Callable[[str], None] = print,
    examples_sha256: Callable[[str], str] | None = None,
    answers: Callable[[str], Program] | None = None,
    start: tuple[Vocabulary, MarkovModel] | None = None,
) -> Run:
    """Explore-compress over `concepts`; `pairs(concept, split)` gives examples, and
    `examples_sha256(concept)`, when given, names them so a resume can check them.
    `answers(concept)` is the program stored with a concept's examples, read only by
    `--args oracle` and fixation guidance (default: the 546's reference programs);
    `start` is a model learned elsewhere (the shipped library, or a run's model file):
    then one pass searches every concept with it, as `vcc learn` does (default: iteration
    0 uniform over the atoms, then explore-compress)."""
    from tqdm import tqdm

    run = Run(out, settings)
    run.check_start("uniform" if start is None else model_sha256(*start))
    if examples_sha256 is not None:
        run.check_examples({c: examples_sha256(c) for c in concepts})
    if settings.args.startswith("predicted"):
        from argpred.predict import default_predictor

        run.check_predictor(default_predictor().card["sha256"])
    explorer = explorer or Explorer()
    subs_on = False
    for it in range(settings.max_iterations):
        before = {r["concept"]: r for r in run.records if r["found"] and r["iteration"] < it}
        programs = [parse(before[c]["program"]) for c in sorted(before)]
        if it == 0:
            vocab, model = start or (Vocabulary(), MarkovModel.uniform(Vocabulary().size, settings.order))
        else:
            vocab, model = fit_model(programs, settings, subs_on)
        write_model(run, it, settings, vocab, model)
        done = {r["concept"] for r in run.records if r["iteration"] == it} | set(before)
        todo = [c for c in concepts if c not in done]
        bar = tqdm(total=len(todo), desc=f"iteration {it}", disable=not progress, unit="concept")

        def done(j: int, r: Result, it: int = it, bar=bar, todo=todo, subs: int = len(vocab.bodies)) -> None:
            c = todo[j]
            test = None
            if r.found:
                tp = pairs(c, "test")
                test = (generalization(r.program, tp, DEFAULT_CONFIG.tau), len(tp))
            run.append({**record_of(c, it, r, test), "subroutines": subs})
            bar.update()
            bar.set_postfix(found=len(run.found()))

        jobs = []
        for c in todo:
            train = pairs(c, "train")
            answer = answers(c) if answers is not None and needs_answer(settings) else None
            chain = Chain(vocab, model, argument_logp(settings, c, train, answer), settings.delta)
            jobs.append((chain, Task.from_pairs(train)))
        explorer.search_many(jobs, settings.budget, done)
        bar.close()
        n_new = sum(1 for r in run.records if r["iteration"] == it and r["found"])
        log(f"iteration {it}: {n_new} new, {len(run.found())} of {len(set(concepts))} found"
            + (f", model with {len(vocab.bodies)} subroutines" if vocab.bodies else ""))
        if len(run.found()) >= len(set(concepts)) or start is not None:
            break
        if n_new == 0:
            if it > 0 and settings.subroutines and not subs_on:
                subs_on = True  # the plain model saturated: compress from now on
                continue
            break
    if settings.parts > 1:
        from search.parts_pass import parts_pass

        parts_pass(run, concepts, pairs, settings, explorer, answers, start, progress, log)
    return run


def write_model(run: Run, it: int, settings: Settings, vocab: Vocabulary, model: MarkovModel) -> None:
    """`model-{it}.json`: the model iteration `it` searched with."""
    files.write_json(run.out / f"model-{it}.json", {
        "iteration": it, "order": settings.order, "subroutines": vocab.to_json(),
        "tokens": [vocab.name(t) for t in range(vocab.size)] + ["<end>"],
        "logp": np.round(model.logp, 6).tolist(),
    }, indent=None)


def model_sha256(vocab: Vocabulary, model: MarkovModel) -> str:
    """A model's identity: its subroutines and transition table."""
    import hashlib

    h = hashlib.sha256(json.dumps(vocab.to_json()).encode())
    h.update(np.ascontiguousarray(model.logp, np.float64).tobytes())
    return h.hexdigest()

