"""A concept's training examples as a search reads them: the pairs for the host, their
input scenes and output targets loaded once for the device."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from vccjax.machine.config import DEFAULT_CONFIG, VCCConfig
from vccjax.machine.match import Target, load_target
from vccjax.machine.scene import Scene
from vccjax.machine.state import SceneConst, load_scene, stack


@dataclasses.dataclass
class Task:
    """A concept's training examples, loaded once for the device."""

    pairs: list[tuple[Scene, Scene]]
    consts: SceneConst  # (E, ...)
    targets: Target  # (E, ...)

    @classmethod
    def from_pairs(cls, pairs: Sequence[tuple[Scene, Scene]], cfg: VCCConfig = DEFAULT_CONFIG) -> Task:
        if not pairs:
            raise ValueError("a task needs at least one example pair")
        return cls(list(pairs), stack([load_scene(a, cfg) for a, _ in pairs]),
                   stack([load_target(b, cfg) for _, b in pairs]))

    @property
    def n_examples(self) -> int:
        return len(self.pairs)
