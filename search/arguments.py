"""What the search believes about arguments: log p(argument | instruction) for a concept,
from its example pairs, an answer program, or a teacher's hint.

Modes (`vcc induce --args`, `vcc learn`):
- uniform: every value of every instruction's domain, equally likely;
- predicted: `set_shape_attn` and `set_color_attn` from the argument CNN on the training
  pairs (arguments under 0.55 dropped, an instruction with none left out;
  `argpred.predict`); `fill_color` the colours some object gains in the pairs
  (`argpred.gained`; `fill="predicted"`: from the CNN as the filters); the filters'
  values the objects acted on rule out dropped, those the changed objects' kinds or a
  landmark point in raised (`argpred.acted`; `filters="acted"`: dropped only,
  `filters="network"`: the CNN's alone); `fixate` and `imagine_object` uniform;
- oracle: uniform over the values an answer program uses, an instruction with arguments
  it never uses left out (what a perfect predictor gives; a research setting that reads
  the answer, never a default);
- +fixation: `fixate` takes the teacher's values only (the paper's pointing teacher; from
  the answer program, or given by the user as `vcc learn --fixate`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from search.chain import uniform_args
from vccjax.machine.instructions import NAMES, OP, arg_domain
from vccjax.machine.program import Program
from vccjax.machine.scene import Scene

MODES = ("uniform", "oracle", "uniform+fixation", "predicted", "predicted+fixation")


def uniform_over(values: Sequence[int], name: str) -> np.ndarray:
    """log p uniform over `values` of instruction `name`'s domain; -inf elsewhere."""
    used = sorted(set(values))
    lp = np.full(len(arg_domain(name)), -np.inf)
    if used:
        lp[used] = -math.log(len(used))
    return lp


def used_values(program: Program, name: str) -> list[int]:
    """The argument values `program` gives instruction `name`."""
    return [a for o, a in zip(program.ops, program.args, strict=True) if o == OP[name]]


def argument_logp(mode: str, pairs: Sequence[tuple[Scene, Scene]] | None = None, answer: Program | None = None,
                  fixate: Sequence[str] | None = None, fallback: bool = False,
                  threshold: float | None = None, fill: str = "gained",
                  filters: str = "acted+raised") -> dict[int, np.ndarray]:
    """log p(argument | instruction) under `mode` (see the module's docstring). `answer`
    is needed by oracle and, without `fixate`, by +fixation; `pairs` by predicted, which
    keeps the arguments at or above `threshold` (default the paper's 0.55) and takes
    `fill_color`'s as `fill` says ('gained' or 'predicted'), the filters' as `filters`
    says ('acted+raised', 'acted' or 'network'). With `fallback`, a predicted function
    none of whose arguments pass keeps the network's probabilities instead of being left out; a
    function the pairs' rules leave no value (fill_color read from the pairs is exact)
    has none to fall back on."""
    if mode not in MODES:
        raise ValueError(f"--args must be one of {', '.join(MODES)}, got {mode!r}")
    out = uniform_args()
    if mode == "oracle":
        if answer is None:
            raise ValueError("--args oracle reads the concept's answer program, and this concept has none")
        return {OP[name]: uniform_over(used_values(answer, name), name) for name in NAMES if arg_domain(name)}
    if mode.startswith("predicted"):
        from argpred.predict import THRESHOLD, argument_logp as predicted, default_predictor

        if not pairs:
            raise ValueError("--args predicted needs the concept's training pairs")
        from argpred.acted import with_filters
        from argpred.gained import with_fill

        threshold = THRESHOLD if threshold is None else threshold
        probs = with_filters(with_fill(default_predictor().for_pairs(pairs), pairs, fill), pairs, filters,
                             threshold=threshold)
        for name, lp in predicted(probs, threshold).items():
            exact = name == "fill_color" and fill == "gained"
            p = np.asarray(probs[name], np.float64)
            if fallback and not exact and not np.isfinite(lp).any() and p.sum() > 0:
                with np.errstate(divide="ignore"):  # a value the pairs rule out stays out
                    lp = np.log(p / p.sum())
            out[OP[name]] = lp
    if mode.endswith("+fixation"):
        if fixate is not None:
            domain = arg_domain("fixate")
            unknown = [v for v in fixate if v not in domain]
            if unknown or not fixate:
                raise ValueError(f"--fixate {','.join(fixate)}: each value must be one of {', '.join(domain)}")
            out[OP["fixate"]] = uniform_over([domain.index(v) for v in fixate], "fixate")
        elif answer is None:
            raise ValueError("fixation guidance reads the teacher's fixations from the concept's answer program, "
                             "and this concept has none")
        else:
            out[OP["fixate"]] = uniform_over(used_values(answer, "fixate"), "fixate")
    return out
