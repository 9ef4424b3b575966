"""The argument CNN (paper, "Argument prediction"): a convolution over each example's
(21, 15, 15) features, max-pooled over positions, summed over the examples, one
sigmoid per (function, argument) label. Summing over examples lets every example
vote: an argument several examples show is more certain.

`hidden=0` is the paper's single convolution (straight to the labels); `hidden>0`
puts `depth` ReLU convolutions of that many channels before it (see `docs/argpred.md`
for what each gives). Two layers see 5x5 cells: an object and the cell a moved one
lands on beside it.

`pool="hidden"` max-pools the hidden channels over the grid first and then mixes them
into labels, so a label can weigh what the whole example shows (a changed object of
another shape says "no shape filter"); `pool="labels"` (the default) pools each label's
own map, which sees an object and its neighbours only. Measured in docs/argpred.md: far
fewer extra arguments, far lower recall; not shipped.

`evidence="relu"` keeps each example's pooled logit at or above zero before the sum:
an example that does not show an argument then says nothing against it. Under
"signed" (the paper's sum) the examples of an "A and B" concept that hold no object
of B's colour outvote the ones that show B, and B's filter is lost. The bias starts
at `bias_start`, since the sum of ten non-negative terms would start every label
near probability one.

`evidence="shown"` lets an example speak, for or against, only of a value it shows: a
shape or colour filter's value where its input holds an object of it, a fill's colour
where its output does (`shown`). An "A and B" example with no object of B's colour
says nothing of B (as under "relu"), while an example whose star stays put where a
star filter would have moved it still counts against the filter (as under "signed").
"""

from __future__ import annotations

import flax.linen as nn
import jax
import jax.numpy as jnp

from argpred.data import LABELS
from vccjax.machine.instructions import COLORS, SHAPES

EVIDENCE = ("signed", "relu", "shown")
_COLOR0 = len(SHAPES)  # the first input colour channel (argpred.features)
_DIFF0 = len(SHAPES) + len(COLORS) + 1  # the first output-minus-input channel


def shown(x: jax.Array) -> jax.Array:
    """(..., 21, 15, 15) features -> (..., labels) 1 where the example shows the label's
    value: an input object of a filter's shape or colour, an output object of a fill's colour."""
    x = x.astype(jnp.float32)
    cols = []
    for f, v in LABELS:
        if f == "set_shape_attn":
            grid = x[..., SHAPES.index(v), :, :]
        elif f == "set_color_attn":
            grid = x[..., _COLOR0 + COLORS.index(v), :, :]
        else:  # fill_color: the output's colour v is input plus change
            grid = x[..., _COLOR0 + COLORS.index(v), :, :] + x[..., _DIFF0 + _COLOR0 + COLORS.index(v), :, :]
        cols.append((grid.max(axis=(-2, -1)) > 0).astype(jnp.float32))
    return jnp.stack(cols, axis=-1)


class ArgNet(nn.Module):
    hidden: int = 32
    kernel: int = 3
    depth: int = 1  # hidden convolutions (when hidden > 0)
    evidence: str = "signed"  # "relu" / "shown": which examples may speak of a label (see above)
    bias_start: float = -4.0  # the bias's first value under "relu" (zero under "signed")
    pool: str = "labels"  # "hidden": pool the hidden channels over positions, then a dense layer (see below)

    @nn.compact
    def __call__(self, x: jax.Array, mask: jax.Array) -> jax.Array:
        """x (B, E, 21, 15, 15), mask (B, E) of real examples -> logits (B, labels)."""
        h = jnp.moveaxis(x.astype(jnp.float32), -3, -1)  # channels last
        if self.hidden:
            for k in range(self.depth):
                name = "conv_hidden" if k == 0 else f"conv_hidden_{k + 1}"
                h = nn.relu(nn.Conv(self.hidden, (self.kernel, self.kernel), name=name)(h))
            if self.pool == "hidden":  # what the whole grid shows, then the labels: a veto can be learned
                h = nn.Dense(len(LABELS), use_bias=False, name="dense_out")(h.max(axis=(-3, -2)))[..., None, None, :]
            elif self.pool == "labels":
                h = nn.Conv(len(LABELS), (1, 1), use_bias=False, name="conv_out")(h)
            else:
                raise ValueError(f"unknown pool {self.pool!r} (labels or hidden)")
        else:
            h = nn.Conv(len(LABELS), (self.kernel, self.kernel), use_bias=False, name="conv_out")(h)
        pooled = h.max(axis=(-3, -2))  # (B, E, labels)
        if self.evidence == "relu":
            pooled = nn.relu(pooled)
        elif self.evidence == "shown":
            pooled = pooled * shown(x)
        elif self.evidence != "signed":
            raise ValueError(f"unknown evidence {self.evidence!r} ({', '.join(EVIDENCE)})")
        start = self.bias_start if self.evidence == "relu" else 0.0
        bias = self.param("bias", nn.initializers.constant(start), (len(LABELS),))
        return (pooled * mask[..., None]).sum(axis=1) + bias
