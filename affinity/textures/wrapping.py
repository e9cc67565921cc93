"""Texture wrap modes as the material authors them (issue 55): what a renderer reads outside [0, 1].

The filtering of :mod:`affinity.textures.filtering` repeats. A map whose wrap is not ``repeat`` on both
axes (UsdUVTexture ``wrapS``/``wrapT``, MaterialX ``uaddressmode``/``vaddressmode``, MTL ``-clamp on``:
:attr:`affinity.loaders.texturemaps.TextureMap.wrap`) is read through :class:`WrappedTexture`, which moves
every sample into the texture first, per axis:

- ``clamp``: to the centres of the edge texels, so bilinear filtering reads the edge texel (clamp to edge);
- ``mirror``: folded back at every edge (a triangle wave of period 2), then as ``clamp``;
- ``black``: as ``clamp`` inside [0, 1], 0 outside (clamp to a black border);
- ``repeat``: unchanged.

The bounds that let the visible reading skip regions (:func:`affinity.textures.visible.crease_bound`) get
texel boxes moved the same way (:meth:`WrappedTexture.boxed`): clamped boxes are clipped (clamping is
monotone, so the clipped box holds every texel read), and a ``mirror`` or ``black`` box that leaves the
texture gets no bound (NaN: the region is sampled, not skipped).
"""

from __future__ import annotations

import numpy as np

WRAPS = ("repeat", "clamp", "mirror", "black")


class WrappedTexture:
    """A decoded texture (:class:`affinity.textures.decode.DecodedTexture`) read with the wrap modes ``wrap``
    (u, v), each one of :data:`WRAPS`: the same attributes, its ``packed`` sampler and bounds moved into it."""

    def __init__(self, texture, wrap: tuple[str, str]):
        self.texture, self.wrap = texture, wrap

    pixels = property(lambda self: self.texture.pixels)
    pyramid = property(lambda self: self.texture.pyramid)  # built lazily, once, by the texture
    slopes = property(lambda self: self.texture.slopes)
    looks_like_normal_map = property(lambda self: self.texture.looks_like_normal_map)

    @property
    def packed(self) -> _WrappedSampler:
        height, width = self.pixels.shape[:2]
        return _WrappedSampler(self.texture.packed, self.wrap, width, height)

    def boxed(self, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Texel boxes from ``low`` to ``high`` (N, 2) texel coordinates moved as the samples are (see the
        module docstring); NaN corners where a box gets no bound."""
        low, high = low.copy(), high.copy()
        height, width = self.pixels.shape[:2]
        for axis, (mode, size) in enumerate(zip(self.wrap, (width, height))):
            if mode == "clamp":
                np.clip(low[:, axis], 0, size - 1, out=low[:, axis])
                np.clip(high[:, axis], 0, size - 1, out=high[:, axis])
            elif mode in ("mirror", "black"):
                outside = (low[:, axis] < 0) | (high[:, axis] > size - 1)
                low[outside], high[outside] = np.nan, np.nan
        return low, high


class _WrappedSampler:
    """A packed texture's ``sample(uv)`` with uv moved into the texture first (:func:`wrapped_uv`)."""

    def __init__(self, packed, wrap: tuple[str, str], width: int, height: int):
        self.packed, self.wrap, self.size = packed, wrap, (width, height)

    def sample(self, uv: np.ndarray) -> np.ndarray:
        moved, black = wrapped_uv(uv, self.wrap, self.size)
        seen = self.packed.sample(moved)
        if black is not None:
            seen[black] = 0.0
        return seen


def wrapped_uv(uv: np.ndarray, wrap: tuple[str, str], size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray | None]:
    """(N, 2) float64 uv moved into the texture of ``size`` (width, height) texels by the wrap modes (u, v), and
    (N,) bool the samples a ``black`` border reads (None when no axis has one).

    >>> wrapped_uv(np.array([[1.5, -0.25], [0.5, 0.5]]), ("clamp", "mirror"), (4, 4))[0].tolist()
    [[0.875, 0.25], [0.5, 0.5]]
    """
    moved = np.array(uv, dtype=np.float64)
    black = None
    for axis, (mode, texels) in enumerate(zip(wrap, size)):
        if mode == "repeat":
            continue
        u = moved[:, axis]
        if mode == "black":
            outside = (u < 0) | (u > 1)
            black = outside if black is None else black | outside
        if mode == "mirror":
            u = 1 - np.abs(np.mod(u, 2) - 1)
        moved[:, axis] = np.clip(u, 0.5 / texels, 1 - 0.5 / texels)
    return moved, black
