"""Texture filtering as a renderer does it at the base level, and a min/max pyramid for bounds.

Texture coordinates follow OpenGL: ``(0, 0)`` is the bottom-left of the image,
``v`` grows upward, texel centres sit at half-integers, and coordinates wrap
(repeat) outside [0, 1]. Texel coordinates (``x``, ``y``) are continuous with
texel ``i``'s centre at ``i``: ``x = u W - 1/2``, ``y = (1 - v) H - 1/2``.
"""

from __future__ import annotations

import numpy as np


def texel_coordinates(uv: np.ndarray, width: int, height: int) -> np.ndarray:
    """(..., 2) float64 texel coordinates (x, y) of uv (..., 2)."""
    uv = np.asarray(uv, dtype=np.float64)
    return np.stack([uv[..., 0] * width - 0.5, (1.0 - uv[..., 1]) * height - 0.5], axis=-1)


def sample_bilinear(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Bilinear texture filtering with repeat wrapping.

    Parameters
    ----------
    image : (H, W, C) float or uint8
    uv : (N, 2) float, OpenGL texture coordinates

    Returns
    -------
    (N, C) float32, in the image's own units (0-255 for uint8).
    """
    height, width, channels = image.shape
    xy = texel_coordinates(uv, width, height)
    x0, y0 = np.floor(xy[:, 0]), np.floor(xy[:, 1])
    fx, fy = (xy[:, 0] - x0).astype(np.float32)[:, None], (xy[:, 1] - y0).astype(np.float32)[:, None]
    x0 = x0.astype(np.int64) % width
    y0 = y0.astype(np.int64) % height
    x1, y1 = (x0 + 1) % width, (y0 + 1) % height
    flat = image.reshape(-1, channels)
    row0, row1 = y0 * width, y1 * width

    def texel(row, column):
        return flat[row + column].astype(np.float32)

    top = texel(row0, x0) * (1 - fx) + texel(row0, x1) * fx
    bottom = texel(row1, x0) * (1 - fx) + texel(row1, x1) * fx
    return top * (1 - fy) + bottom * fy


class RangePyramid:
    """Per-channel minimum and maximum over blocks of 2^k x 2^k texels, level k = 0, 1, ...

    A box of texels is covered by at most 2 x 2 blocks of the first level whose block is
    at least as wide as the box, so :meth:`channel_range` answers any box in four lookups.
    Memory: two pyramids of about 1/3 of the image each (uint8 like the image).
    """

    def __init__(self, image: np.ndarray):
        self.shape = image.shape
        self.levels = [(image, image)]
        low, high = image, image
        while max(low.shape[:2]) > 1:
            low, high = _reduced(low, np.minimum), _reduced(high, np.maximum)
            self.levels.append((low, high))

    def channel_range(self, x0: np.ndarray, x1: np.ndarray, y0: np.ndarray, y1: np.ndarray) -> np.ndarray:
        """(N,) float64: the largest channel's (max - min) over the texel boxes [x0, x1] x [y0, y1]
        (inclusive int64 texel indices, (N,) each, inside the image)."""
        extent = np.maximum(x1 - x0, y1 - y0) + 1
        level = np.minimum(np.ceil(np.log2(np.maximum(extent, 1))).astype(np.int64), len(self.levels) - 1)
        result = np.zeros(len(x0))
        for k in np.unique(level).tolist():  # one pass per pyramid level (at most ~14), not per box
            rows = np.flatnonzero(level == k)
            low, high = self.levels[k]
            bx0, bx1, by0, by1 = x0[rows] >> k, x1[rows] >> k, y0[rows] >> k, y1[rows] >> k
            lows = np.stack([low[by, bx] for by in (by0, by1) for bx in (bx0, bx1)]).min(axis=0)
            highs = np.stack([high[by, bx] for by in (by0, by1) for bx in (bx0, bx1)]).max(axis=0)
            result[rows] = (highs.astype(np.float64) - lows).max(axis=-1)
        return result


def _reduced(image: np.ndarray, reduce) -> np.ndarray:
    """One pyramid level: ``reduce`` over 2 x 2 blocks, an odd last row or column kept as its own block."""
    height, width = image.shape[:2]
    if height % 2 or width % 2:
        image = np.pad(image, ((0, height % 2), (0, width % 2), (0, 0)), mode="edge")
    return reduce.reduce(reduce.reduce(image.reshape(image.shape[0] // 2, 2, image.shape[1] // 2, 2, -1), axis=3),
                         axis=1)
