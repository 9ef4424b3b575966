"""One concept's search space: the Markov chain over parameterised program portions.

A portion is a token (atom or subroutine) with values for its atoms' arguments; its
cost after token p is -log T[p, token] - sum log p(arg | atom) (paper eq. 4). Costs
are counted in whole bins of `delta` nats (each part rounded up), so that the number
of programs under a description-length cutoff can be counted exactly by dynamic
programming and the cutoff for a budget of M programs found without enumerating them.

Syntax is a small automaton run alongside: nothing before `scene_parse`, no second
one, one loop level, a loop body with `top_down_attend` and `next_object` and none of
the instructions banned in it; a program may end only outside a loop.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import math
from collections.abc import Mapping

import numpy as np

from search.model import MarkovModel, Vocabulary
from vccjax.machine.instructions import FORBIDDEN_IN_LOOP, NAMES, OP, arg_domain

NOT_STARTED, OUTSIDE = 0, 1  # then 2 + flags (1: top_down_attend seen, 2: next_object seen)
N_SYN = 6
_FORBIDDEN = {OP[n] for n in FORBIDDEN_IN_LOOP}
MAX_COMBOS = 4096  # argument combinations kept per token (most probable first)


def atom_syntax(op: int, syn: int) -> int:
    """The syntax state after `op`, or -1 where the program cannot continue so."""
    if syn == NOT_STARTED:
        return OUTSIDE if op == OP["scene_parse"] else -1
    if op == OP["scene_parse"]:
        return -1
    if syn == OUTSIDE:
        if op == OP["loop_end"]:
            return -1
        return 2 if op == OP["loop_start"] else OUTSIDE
    flags = syn - 2
    if op in _FORBIDDEN:
        return -1
    if op == OP["loop_end"]:
        return OUTSIDE if flags == 3 else -1
    if op == OP["top_down_attend"]:
        flags |= 1
    elif op == OP["next_object"]:
        flags |= 2
    return 2 + flags


def uniform_args() -> dict[int, np.ndarray]:
    return {OP[n]: np.full(len(d), -math.log(len(d))) for n in NAMES if (d := arg_domain(n))}


@dataclasses.dataclass
class Chain:
    """Portions, their costs in bins, and the syntax automaton for one concept."""

    vocab: Vocabulary
    model: MarkovModel
    arg_logp: Mapping[int, np.ndarray]  # op -> log p over its domain (-inf: excluded)
    delta: float = 0.01

    def __post_init__(self) -> None:
        v = self.vocab
        tok, argbins, argnats, ops, args = [], [], [], [], []
        for t in range(v.size):
            atoms = v.atoms(t)
            slots = [a for a in atoms if arg_domain(NAMES[a])]
            choices = []
            for a in slots:
                lp = np.asarray(self.arg_logp.get(a, np.full(len(arg_domain(NAMES[a])), -np.inf)))
                choices.append([(i, float(lp[i])) for i in range(len(lp)) if np.isfinite(lp[i])])
            combos = sorted(itertools.product(*choices), key=lambda c: -sum(x[1] for x in c))
            for combo in combos[:MAX_COMBOS]:
                it = iter(combo)
                a_list = tuple(next(it)[0] if arg_domain(NAMES[a]) else 0 for a in atoms)
                nats = -sum(x[1] for x in combo)
                tok.append(t)
                ops.append(atoms)
                args.append(a_list)
                argnats.append(nats)
                argbins.append(sum(self._bins(-x[1]) for x in combo))
        self.tok = np.array(tok, np.int32)
        self.ops, self.args = ops, args
        width = max(len(o) for o in ops)  # the same as tuples and as (portions, atoms) arrays, -1 padded
        self.op_mat = np.full((len(ops), width), -1, np.int32)
        self.arg_mat = np.zeros((len(ops), width), np.int32)
        for z, (o, a) in enumerate(zip(ops, args)):
            self.op_mat[z, : len(o)], self.arg_mat[z, : len(a)] = o, a
        self.argnats = np.array(argnats)
        self.argbins = np.array(argbins, np.int64)
        lp = self.model.logp
        self.trans_nats = -lp
        self.trans_bins = np.vectorize(self._bins)(-lp).astype(np.int64)
        self.end = v.end
        # syntax: state after each token from each state
        self.next_syn = np.full((v.size, N_SYN), -1, np.int32)
        for t in range(v.size):
            for s in range(N_SYN):
                cur = s
                for a in v.atoms(t):
                    cur = atom_syntax(a, cur)
                    if cur < 0:
                        break
                self.next_syn[t, s] = cur
        self.min_rest = self._min_rest()

    def _bins(self, nats: float) -> int:
        return max(1, math.ceil(nats / self.delta - 1e-9)) if nats > 0 else 0

    @property
    def n_portions(self) -> int:
        return len(self.tok)

    def portion_cost(self, last: np.ndarray, z: np.ndarray) -> np.ndarray:
        return self.trans_bins[last, self.tok[z]] + self.argbins[z]

    def _min_rest(self) -> np.ndarray:
        """(V+1, N_SYN) fewest bins from (last token, syntax) to a complete program."""
        big = np.iinfo(np.int64).max // 4
        rest = np.full((self.end + 1, N_SYN), big, np.int64)
        rest[:, OUTSIDE] = self.trans_bins[:, self.end]
        best_arg = np.full(self.end, big, np.int64)
        np.minimum.at(best_arg, self.tok, self.argbins)
        for _ in range(64):  # Bellman-Ford; paths are short
            new = rest.copy()
            for s in range(N_SYN):
                nxt = self.next_syn[:, s]
                ok = (nxt >= 0) & (best_arg < big)
                t = np.nonzero(ok)[0]
                if len(t):
                    via = self.trans_bins[:, t] + best_arg[t][None, :] + rest[t, nxt[t]][None, :]
                    new[:, s] = np.minimum(new[:, s], via.min(1))
            if np.array_equal(new, rest):
                break
            rest = new
        return rest

    # ---- counting ----------------------------------------------------------------------
    def count_table(self, budget: int, max_bins: int | None = None,
                    root: tuple[int, int] | None = None) -> np.ndarray:
        """Programs from the start with cost <= b, for b = 0.. until `budget` is reached
        (cumulative counts; the last entry is the first >= budget). `root` (last token,
        syntax state) counts the continuations of a prefix ending there instead."""
        max_bins = max_bins or int(200 / self.delta)
        v1 = self.end + 1
        # classes: (token, arg bins) with multiplicity
        key = self.tok.astype(np.int64) * (1 << 32) + self.argbins
        uniq, mult = np.unique(key, return_counts=True)
        c_tok, c_arg = (uniq >> 32).astype(np.int64), uniq & ((1 << 32) - 1)
        src, dst, off, mul = [], [], [], []
        for p in range(v1):
            for s in range(N_SYN):
                nxt = self.next_syn[c_tok, s]
                ok = nxt >= 0
                k = np.nonzero(ok)[0]
                src.append(np.full(len(k), p * N_SYN + s))
                dst.append(c_tok[k] * N_SYN + nxt[k])
                off.append(self.trans_bins[p, c_tok[k]] + c_arg[k])
                mul.append(mult[k].astype(float))
        src, dst, off, mul = (np.concatenate(x) for x in (src, dst, off, mul))
        rows = v1 * N_SYN
        end_cost = np.full(rows, np.iinfo(np.int64).max)
        end_cost[OUTSIDE::N_SYN] = self.trans_bins[:, self.end]
        last, syn = root if root is not None else (self.end, NOT_STARTED)
        start = last * N_SYN + syn
        table = np.zeros((rows, 1024))
        counts = []
        for b in range(max_bins + 1):
            if b >= table.shape[1]:
                table = np.concatenate([table, np.zeros_like(table)], axis=1)
            ok = off <= b
            vals = table[dst[ok], b - off[ok]] * mul[ok]
            table[:, b] = (end_cost <= b) + np.bincount(src[ok], weights=vals, minlength=rows)
            counts.append(table[start, b])
            if table[start, b] >= budget:
                break
        return np.array(counts)

    def program_bins(self, portions: list[int]) -> int:
        last, total = self.end, 0
        for z in portions:
            total += int(self.portion_cost(np.array([last]), np.array([z]))[0])
            last = int(self.tok[z])
        return total + int(self.trans_bins[last, self.end])

    def cheapest(self, ops: tuple[int, ...], args: tuple[int, ...]) -> tuple[float, list[int]] | None:
        """(description length in nats, portions) of an atomic program's cheapest spelling in
        this chain's tokens (subroutine calls where their bodies match), or None where the
        chain cannot spell it (an argument it rules out, or broken syntax)."""
        if not hasattr(self, "_portion_of"):
            self._portion_of = {(int(t), tuple(a)): z for z, (t, a) in reversed(list(enumerate(zip(self.tok, self.args))))}
        n, inf = len(ops), math.inf
        best: list[dict[tuple[int, int], tuple[float, list[int]]]] = [dict() for _ in range(n + 1)]
        best[0][(self.end, NOT_STARTED)] = (0.0, [])
        for i in range(n):
            for (last, syn), (nats, path) in best[i].items():
                for t in range(self.vocab.size):
                    atoms = self.vocab.atoms(t)
                    z = self._portion_of.get((t, tuple(args[i:i + len(atoms)])))
                    nxt = self.next_syn[t, syn]
                    if z is None or nxt < 0 or tuple(ops[i:i + len(atoms)]) != atoms:
                        continue
                    cost = nats + float(self.trans_nats[last, t] + self.argnats[z])
                    key = (t, int(nxt))
                    if cost < best[i + len(atoms)].get(key, (inf,))[0]:
                        best[i + len(atoms)][key] = (cost, path + [z])
        ends = [(nats + float(self.trans_nats[last, self.end]), path)
                for (last, syn), (nats, path) in best[n].items() if syn == OUTSIDE]
        return min(ends, key=lambda e: e[0]) if ends else None

    def program_nats(self, portions: list[int]) -> float:
        last, total = self.end, 0.0
        for z in portions:
            total += float(self.trans_nats[last, self.tok[z]] + self.argnats[z])
            last = int(self.tok[z])
        return total + float(self.trans_nats[last, self.end])


_TABLES: dict[bytes, np.ndarray] = {}


def cutoff_for_budget(chain: Chain, budget: int, root: tuple[int, int] | None = None) -> tuple[int, np.ndarray]:
    """The description-length cutoff (bins) of the `budget` most probable programs, and the
    cumulative count table (rank of a program of cost b = table[b - 1] + 1); with `root`
    (last token, syntax state), of a prefix's `budget` most probable continuations.

    The table depends only on the model's transition costs, the syntax and how many
    portions each token has at each argument cost, so concepts whose argument
    distributions differ only in which values they favour share it (cached)."""
    classes, mult = np.unique(chain.tok.astype(np.int64) * (1 << 32) + chain.argbins, return_counts=True)
    key = hashlib.sha256(b"".join(np.ascontiguousarray(a).tobytes() for a in (
        np.array([budget, chain.end, *(root or (-1, -1))]), chain.trans_bins, chain.next_syn, classes, mult))).digest()
    if key not in _TABLES:
        if len(_TABLES) > 256:
            _TABLES.clear()
        _TABLES[key] = chain.count_table(budget, root=root)
    table = _TABLES[key]
    return len(table) - 1, table
