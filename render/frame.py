"""The rasterizer's output image."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Frame:
    """A rendered image of H rows and W columns (row 0 at the top).

    Attributes
    ----------
    face : (H, W) int64
        Index of the quad seen at each pixel, -1 where nothing was drawn.
    attrs : (H, W, K) float64
        Interpolated attributes of that quad; NaN where ``face`` is -1.
    depth : (H, W) float64
        NDC depth in [-1, 1] (smaller is nearer); inf where ``face`` is -1.
    fragments : int
        How many fragments (covered pixel centres, before the depth test) were
        generated: the work measure of the benchmarks.
    """

    face: np.ndarray
    attrs: np.ndarray
    depth: np.ndarray
    fragments: int = 0

    @classmethod
    def empty(cls, height, width, channels) -> Frame:
        """A frame with nothing drawn."""
        return cls(
            face=np.full((height, width), -1, dtype=np.int64),
            attrs=np.full((height, width, channels), np.nan),
            depth=np.full((height, width), np.inf),
        )
