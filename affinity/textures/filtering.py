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


def _corners(width: int, height: int, uv: np.ndarray):
    """The four texels bilinear filtering reads at OpenGL uv (N, 2) with repeat wrapping, as flat indices
    (N,) int64 each (top-left, top-right, bottom-left, bottom-right), and the weights (N, 1) float32 of the
    right and bottom ones."""
    xy = texel_coordinates(uv, width, height)
    x0, y0 = np.floor(xy[:, 0]), np.floor(xy[:, 1])
    fx, fy = (xy[:, 0] - x0).astype(np.float32)[:, None], (xy[:, 1] - y0).astype(np.float32)[:, None]
    x0 = x0.astype(np.int64) % width
    y0 = y0.astype(np.int64) % height
    x1, y1 = (x0 + 1) % width, (y0 + 1) % height
    row0, row1 = y0 * width, y1 * width
    return (row0 + x0, row0 + x1, row1 + x0, row1 + x1), fx, fy


def _blend(texels, fx: np.ndarray, fy: np.ndarray) -> np.ndarray:
    top_left, top_right, bottom_left, bottom_right = texels
    top = top_left + (top_right - top_left) * fx
    bottom = bottom_left + (bottom_right - bottom_left) * fx
    return top + (bottom - top) * fy


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
    flat = image.reshape(-1, channels)
    index, fx, fy = _corners(width, height, uv)
    return _blend([flat.take(i, axis=0).astype(np.float32) for i in index], fx, fy)


class PackedTexture:
    """A uint8 texture of at most four channels with each texel's channels in one uint32, so that bilinear
    filtering gathers one word per texel (the lint samples millions of points per texture).

    ``sample(uv)`` equals :func:`sample_bilinear` of the texture's ``pixels`` (H, W, C) uint8.
    """

    def __init__(self, pixels: np.ndarray):
        height, width, channels = pixels.shape
        padded = np.zeros((height, width, 4), dtype=np.uint8)
        padded[..., :channels] = pixels
        self.shape = pixels.shape
        self.words = padded.view(np.uint32).reshape(-1)

    def sample(self, uv: np.ndarray) -> np.ndarray:
        """(N, C) float32 in 0-255: bilinear samples at OpenGL uv (N, 2), repeating."""
        height, width, channels = self.shape
        index, fx, fy = _corners(width, height, uv)
        words = self.words.take(np.stack(index))  # (4, N) uint32: one gather for the four texels
        texels = words.view(np.uint8).reshape(4, -1, 4)[:, :, :channels].astype(np.float32)
        return _blend(texels, fx, fy)


class RangePyramid:
    """Per-channel minimum and maximum over blocks of 2^k x 2^k texels, level k = 0, 1, ...

    A box of texels is covered by at most 2 x 2 blocks of the first level whose block is
    at least as wide as the box, so :meth:`channel_bounds` answers any box in four lookups.
    Memory: two pyramids of about 1/3 of the image each (uint8 like the image); with
    ``minima=False`` the maxima only (the minima :meth:`channel_bounds` gives are then 0).
    """

    def __init__(self, image: np.ndarray, minima: bool = True):
        self.shape, self.minima = image.shape, minima
        self.levels = [(image if minima else np.zeros_like(image[:1, :1]), image)]
        low, high = image, image
        while max(high.shape[:2]) > 1:
            high = _reduced(high, np.maximum)
            low = _reduced(low, np.minimum) if minima else np.zeros_like(high[:1, :1])
            self.levels.append((low, high))

    def channel_bounds(self, x0: np.ndarray, x1: np.ndarray, y0: np.ndarray,
                       y1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N, C) float64 per-channel minimum and maximum over the texel boxes [x0, x1] x [y0, y1]
        (inclusive int64 texel indices, (N,) each, inside the image)."""
        extent = np.maximum(x1 - x0, y1 - y0) + 1
        level = np.minimum(np.ceil(np.log2(np.maximum(extent, 1))).astype(np.int64), len(self.levels) - 1)
        lows, highs = np.empty((len(x0), self.shape[2])), np.empty((len(x0), self.shape[2]))
        for k in np.unique(level).tolist():  # one pass per pyramid level (at most ~14), not per box
            rows = np.flatnonzero(level == k)
            low, high = self.levels[k]
            bx0, bx1, by0, by1 = x0[rows] >> k, x1[rows] >> k, y0[rows] >> k, y1[rows] >> k
            if not self.minima:
                lows[rows] = 0
            else:
                lows[rows] = np.stack([low[by, bx] for by in (by0, by1) for bx in (bx0, bx1)]).min(axis=0)
            highs[rows] = np.stack([high[by, bx] for by in (by0, by1) for bx in (bx0, bx1)]).max(axis=0)
        return lows, highs


def _reduced(image: np.ndarray, reduce) -> np.ndarray:
    """One pyramid level: ``reduce`` (np.minimum or np.maximum) over 2 x 2 blocks, an odd last row or column
    kept as its own block (elementwise over row pairs, then column pairs: faster than a reduction over tiny
    axes)."""
    height, width = image.shape[:2]
    if height % 2 or width % 2:
        image = np.pad(image, ((0, height % 2), (0, width % 2), (0, 0)), mode="edge")
    rows = reduce(image[0::2], image[1::2])  # pairs of rows: contiguous runs
    half, width, channels = rows.shape
    pairs = rows.reshape(half, width // 2, 2 * channels)  # each column pair's channels side by side
    return reduce(pairs[..., :channels], pairs[..., channels:])
