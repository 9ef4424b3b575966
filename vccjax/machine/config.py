"""Static machine configuration: every array shape in the emulator derives from it."""

from __future__ import annotations

import dataclasses
import math


@dataclasses.dataclass(frozen=True)
class VCCConfig:
    """Sizes that fix the shapes of the emulator state (hashable, so jit can key on it).

    raster: full-resolution raster width R in pixels (contact, motion, images).
    sub: sub-pixel units per raster pixel; positions are stored as integers in
        units of 1 / (raster * sub) of the workspace, so every geometric decision
        is exact integer arithmetic and the JAX emulator and the reference agree
        bit for bit.
    n_max: object slots.
    hist_max: capacity of the fixation history (a fixation beyond it fails).
    body_max: the longest loop body (a longer body fails / is a syntax error).
    max_width: widest object accepted in a scene (fixes the mask row window).
    """

    raster: int = 64
    sub: int = 16
    n_max: int = 10
    hist_max: int = 32
    body_max: int = 24
    max_width: float = 0.25

    def __post_init__(self) -> None:
        if self.raster < 16 or self.raster > 512:
            raise ValueError(f"raster must be in [16, 512] (int32 geometry), got {self.raster}")
        if self.n_max < 10:
            raise ValueError(f"n_max must be at least 10 (docs/vcc.md section 1), got {self.n_max}")
        if not 0.0 < self.max_width <= 0.5:
            raise ValueError(f"max_width must be in (0, 0.5], got {self.max_width}")

    @property
    def units(self) -> int:
        """Integer position units across the whole workspace."""
        return self.raster * self.sub

    @property
    def words(self) -> int:
        """uint32 words per raster row in the occupancy bitmap."""
        return (self.raster + 31) // 32

    @property
    def mask_rows(self) -> int:
        """Rows in an object's mask window (its tallest possible mask)."""
        return int(math.ceil(self.max_width * self.raster)) + 2

    @property
    def tau(self) -> float:
        """Center tolerance for comparing scenes (docs/vcc.md section 7)."""
        return max(0.02, 1.5 / self.raster)


DEFAULT_CONFIG = VCCConfig()
