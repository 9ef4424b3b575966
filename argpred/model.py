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
"""

from __future__ import annotations

import flax.linen as nn
import jax
import jax.numpy as jnp

from argpred.data import LABELS


class ArgNet(nn.Module):
    hidden: int = 32
    kernel: int = 3
    depth: int = 1  # hidden convolutions (when hidden > 0)
    evidence: str = "signed"  # "relu": an example adds evidence for a label or nothing (see below)
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
        elif self.evidence != "signed":
            raise ValueError(f"unknown evidence {self.evidence!r} (signed or relu)")
        start = 0.0 if self.evidence == "signed" else self.bias_start
        bias = self.param("bias", nn.initializers.constant(start), (len(LABELS),))
        return (pooled * mask[..., None]).sum(axis=1) + bias
