"""`vcc bench emulator`: the batched JAX emulator against the scalar reference
interpreter on the instruction stream of a real search.

The stream: the children a search steps, in its order (the scalar-driven search of
`search.scalar`, recorded: each child is its parent prefix plus one instruction, on all
of its concept's training examples). Both machines start from the same parent states
(computed beforehand, untimed) and step every child by its last instruction on every
example: the reference clones each parent machine and steps it; the JAX emulator steps
the children grouped by instruction, in device calls cut as the search cuts them (its
padded batch sizes up to `batch` rows; for a carry op, the rows that hold an object
apart from those that skip the carry). The first pass over every (instruction, batch)
compiles and is timed apart; each instruction's time is the best of its timed passes. The two
must agree on every child (failure flag and blackboard); the report says whether they do.
"""

from __future__ import annotations

import dataclasses
import time
from collections import Counter
from collections.abc import Sequence

import jax
import jax.numpy as jnp
import numpy as np

from vccjax.machine.config import VCCConfig
from search.device_calls import BUCKETS, piece_sizes
from search.stepping import EMPTY_HANDED, holding_split, replay_loops, step_examples
from vccjax.machine.step import run_batch
from vccjax.machine.instructions import NAMES, OP
from vccjax.machine.program import Program
from vccjax.machine.reference import RefMachine
from vccjax.machine.scene import Scene, scenes_match
from vccjax.machine.state import init_state, load_scene, output_scene, stack


class _Enough(Exception):
    """Raised inside the recorded search once enough children are recorded."""


def record_stream(chains_tasks: Sequence, per_concept: int) -> list[tuple[int, Program, int, int]]:
    """Up to `per_concept` children of each concept's search: (concept index, parent
    prefix, last op, last arg), in the order the search steps them."""
    from search.explore import Searcher
    from search.scalar import ScalarBackend

    out: list[tuple[int, Program, int, int]] = []

    class Recorder(ScalarBackend):
        def root_states(self, task):
            roots = super().root_states(task)
            for m in roots[0]:
                m.prefix = ((), ())
            return roots

        def apply(self, request):
            reply = super().apply(request)
            for i, z in enumerate(request.portions):
                parent = request.states[request.parents[i]][0].prefix
                ops, args = list(parent[0]), list(parent[1])
                steps = list(zip(request.chain.ops[z], request.chain.args[z], strict=True))
                for op, arg in steps[:-1]:  # a subroutine's body but its last instruction joins the prefix
                    ops.append(op)
                    args.append(arg)
                out.append((j, Program(tuple(ops), tuple(args)), int(steps[-1][0]), int(steps[-1][1])))
                for m in reply.states[i]:
                    m.prefix = (tuple(ops) + (steps[-1][0],), tuple(args) + (steps[-1][1],))
                if sum(1 for c in out if c[0] == j) >= per_concept:
                    raise _Enough
            return reply

    for j, (chain, task) in enumerate(chains_tasks):  # noqa: B007 (`j` is read by Recorder.apply)
        try:
            Searcher(Recorder()).search(chain, task, 10**9)
        except _Enough:
            pass
    return out


@dataclasses.dataclass
class Prepared:
    """The stream's children grouped by instruction, with their parents' states."""

    cfg: VCCConfig
    scenes: list[list[Scene]]  # per concept, its example inputs
    children: list[tuple[int, Program, int, int]]
    parents_ref: list[list[RefMachine]]  # per child, its parent's machines (one per example)
    consts: object  # (K, E, ...) SceneConst
    groups: dict[int, dict[str, np.ndarray]]  # op -> rows, tasks, args, and the parents' states (on device)


def prepare(children, scenes: list[list[Scene]], cfg: VCCConfig) -> Prepared:
    """Parent states on both machines (untimed), children grouped by their instruction."""
    consts_k = [stack([load_scene(s, cfg, validate=False) for s in ex]) for ex in scenes]
    consts = stack(consts_k)
    refs, cache_ref, cache_jax = [], {}, {}
    jax_rows = []
    for j, prefix, _, _ in children:
        key = (j, prefix.ops, prefix.args)
        if key not in cache_ref:
            ms = [RefMachine(s, cfg, validate=False) for s in scenes[j]]
            for m in ms:
                m.run(prefix)
            cache_ref[key] = ms
            length = max(16, -(-len(prefix) // 16) * 16)
            if len(prefix):
                ops, args, _ = prefix.arrays(length)
                cache_jax[key] = run_batch(cfg, consts_k[j], jnp.asarray(ops), jnp.asarray(args))
            else:
                cache_jax[key] = jax.vmap(lambda _: init_state(cfg))(jnp.arange(len(scenes[j])))
        refs.append(cache_ref[key])
        jax_rows.append(cache_jax[key])
    groups = {}
    ops = np.array([c[2] for c in children])
    for op in sorted(set(ops.tolist())):
        rows = np.nonzero(ops == op)[0]
        groups[op] = {
            "rows": rows, "tasks": jnp.asarray([children[r][0] for r in rows], jnp.int32),
            "args": jnp.asarray([children[r][3] for r in rows], jnp.int32),
            "states": jax.tree.map(lambda *x: jnp.stack(x), *[jax_rows[r] for r in rows]),
        }
    return Prepared(cfg, scenes, list(children), refs, consts, groups)


def _buckets(batch: int) -> list[int]:
    """The search's bucket sizes, capped at `batch`."""
    return [b for b in BUCKETS if b < batch] + [batch]


def _pieces(n: int, batch: int) -> list[np.ndarray]:
    """Row indices in pieces as the search cuts a batch of n rows (its bucket sizes up to
    `batch`, at the least padded-rows-plus-calls cost), each padded by repeating its first
    row (one compile per size)."""
    out, s = [], 0
    for size in piece_sizes(n, _buckets(batch)):
        idx = np.arange(s, min(n, s + size))
        out.append(np.concatenate([idx, np.full(size - len(idx), idx[0])]))
        s += size
    return out


def _parts(op: int, g: dict, batch: int) -> list[np.ndarray]:
    """A group's rows, a carry op's holders apart (`stepping.holding_split`)."""
    rows = np.arange(len(g["rows"]))
    if op not in EMPTY_HANDED:
        return [rows]
    holding = (np.asarray(g["states"].hand.held) >= 0).any(axis=1)
    return holding_split(op, rows, holding, lambda n: piece_sizes(n, _buckets(batch)))


def batches(p: Prepared, batch: int) -> dict[int, list]:
    """Per instruction, its children in device batches of up to `batch` rows cut as the
    search cuts them, the parents' states gathered in advance (forming batches is the
    search's work, not the machine's)."""
    out = {}
    for op, g in p.groups.items():
        out[op] = [(idx, g["tasks"][idx], jax.tree.map(lambda a, idx=idx: a[idx], g["states"]), g["args"][idx])
                   for part in _parts(op, g, batch) for idx in (part[k] for k in _pieces(len(part), batch))]
    return jax.block_until_ready(out)


def step_jax(p: Prepared, prepared: dict[int, list]) -> tuple[dict[int, list], dict[int, float]]:
    """Every child stepped by its instruction, one device call per batch; (states per op,
    seconds per op)."""
    out, secs = {}, {}
    for op, pieces in prepared.items():
        t0 = time.perf_counter()
        results = [(idx, _step(p.cfg, op, p.consts, tasks, states, args)) for idx, tasks, states, args in pieces]
        jax.block_until_ready([r for _, r in results])
        secs[op] = time.perf_counter() - t0
        out[op] = results
    return out, secs


def _step(cfg: VCCConfig, op: int, consts, tasks, states, args):
    """One instruction's rows in one call; a closed loop's further iterations are
    replayed in one more call (`stepping.replay_loops`, each body instruction by its own
    code), not in a traced loop that runs every instruction's code."""
    if op != OP["loop_end"]:
        return step_examples(cfg, op, consts, tasks, states, args)
    return replay_loops(cfg, consts, tasks, step_examples(cfg, op, consts, tasks, states, args, False))


def step_reference(p: Prepared) -> tuple[list[list[RefMachine]], dict[int, float]]:
    """Every child stepped by its instruction on cloned parent machines; (machines, seconds per op)."""
    kids: list[list[RefMachine] | None] = [None] * len(p.children)
    secs: Counter = Counter()
    for op, g in p.groups.items():
        t0 = time.perf_counter()
        for r in g["rows"]:
            arg = p.children[r][3]
            ms = []
            for m in p.parents_ref[r]:
                k = m.clone()
                k.step(op, arg)
                ms.append(k)
            kids[r] = ms
        secs[op] = time.perf_counter() - t0
    return kids, dict(secs)


def agree(p: Prepared, jax_out: dict, ref_kids: list) -> bool:
    """Failure flags and blackboards of every child on every example. A replayed loop
    stops a program that failed on some example (the search drops it), so for `loop_end`
    children the flags agree as "failed on some example", and the blackboards of those
    that ran on every example."""
    consts = jax.device_get(p.consts)
    for op, results in jax_out.items():
        g = p.groups[op]
        for idx, states in results:
            states = jax.device_get(states)
            for k, i in enumerate(idx):
                r = int(g["rows"][i])
                j = p.children[r][0]
                if op == OP["loop_end"]:
                    dead = bool(states.control.failed[k].any())
                    if dead != any(m.failed for m in ref_kids[r]):
                        return False
                    if dead:
                        continue
                for e, m in enumerate(ref_kids[r]):
                    if bool(states.control.failed[k, e]) != m.failed:
                        return False
                    if not m.failed and m.blackboard.parsed:
                        c = jax.tree.map(lambda a, j=j, e=e: a[j, e], consts)
                        s = jax.tree.map(lambda a, k=k, e=e: a[k, e], states)
                        if not scenes_match(output_scene(c, s, p.cfg), m.output_scene(), 1e-9):
                            return False
    return True


def measure(p: Prepared, batch: int, repeats: int = 3) -> dict:
    """Compile pass apart, then the best of `repeats` timed passes of each machine."""
    prepared = batches(p, batch)
    t0 = time.perf_counter()
    jax_out, _ = step_jax(p, prepared)
    compile_s = time.perf_counter() - t0
    per_jax: dict[int, float] = {}
    per_ref: dict[int, float] = {}
    for _ in range(repeats):  # each op's best pass on each machine: a busy moment spoils one pass, not the figure
        _, sj = step_jax(p, prepared)
        per_jax = {op: min(t, per_jax.get(op, np.inf)) for op, t in sj.items()}
        kids, sr = step_reference(p)
        per_ref = {op: min(t, per_ref.get(op, np.inf)) for op, t in sr.items()}
    best_jax, best_ref = sum(per_jax.values()), sum(per_ref.values())
    n = len(p.children)
    per_op = {}
    for op, g in p.groups.items():
        m = len(g["rows"])
        per_op[NAMES[op]] = {"programs": m, "jax_per_second": round(m / per_jax[op]),
                             "reference_per_second": round(m / per_ref[op]),
                             "ratio": round(per_ref[op] / per_jax[op], 2)}
    return {"batch": batch, "programs": n, "examples": len(p.scenes[0]),
            "first_pass_seconds_with_compile": round(compile_s, 2),
            "jax_seconds": round(best_jax, 4), "reference_seconds": round(best_ref, 4),
            "jax_programs_per_second": round(n / best_jax), "reference_programs_per_second": round(n / best_ref),
            "ratio": round(best_ref / best_jax, 2), "agree": agree(p, jax_out, kids), "per_instruction": per_op}
