"""An Image Texture node's extension (Extend, Clip, Mirror) as texels the repeating sampler reads exactly.

The visible reading's sampler repeats (:mod:`affinity.textures.filtering`). Blender's other extensions are laid
out as a larger image that, repeated, reads as the node does wherever the mesh's uv reach, with the map's uv
moved onto it (``TextureMap`` scale and offset):

- Mirror: the image beside its mirror images, 2W x 2H, read at uv / 2 (its period is two images);
- Extend and Clip: the image inside a margin of P texels (its edge texels repeated, or transparent black), read
  at (uv W + P) / (W + 2P): exact for uv up to P texels outside [0, 1]. P covers the mesh's uv, at most one
  image wide (beyond that the uv read the margin's far side repeated, and a note says so).

Texel i of the image keeps its centre at the same uv: ``(i + 1/2) / W`` maps to the laid-out image's texel
i (Mirror) or i + P (Extend, Clip). The texel unit stays the image's own (the held header's size).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..textures.decode import DecodedTexture

#: Extensions laid out here; Repeat is the sampler's own.
LAID_OUT = ("EXTEND", "CLIP", "MIRROR")


@dataclass(frozen=True)
class Layout:
    """How the uv move onto a laid-out image: ``u' = u * scale + offset`` per axis, and the margin (texels)."""

    scale: tuple[float, float]
    offset: tuple[float, float]
    margin: tuple[int, int] = (0, 0)


def margins(uv_low: np.ndarray, uv_high: np.ndarray, size: tuple[int, int]) -> tuple[tuple[int, int], bool]:
    """(P_x, P_y) texels covering uv from ``uv_low`` to ``uv_high`` (2,) outside [0, 1] (and one texel for the
    filter), at most the image's width and height; and whether the uv reach beyond that.

    >>> margins(np.array([-0.1, 0.2]), np.array([1.0, 0.9]), (40, 20))
    ((5, 1), False)
    """
    size_array = np.array(size, dtype=np.float64)
    outside = np.maximum(np.maximum(-uv_low, uv_high - 1.0), 0.0) * size_array
    needed = np.ceil(outside).astype(np.int64) + 1
    capped = np.minimum(needed, np.array(size))
    return (int(capped[0]), int(capped[1])), bool((needed > capped).any())


def laid_out(texture: DecodedTexture, key: str, extension: str, margin: tuple[int, int]) -> tuple[DecodedTexture,
                                                                                                  Layout]:
    """The texture laid out for ``extension`` (module docstring), held under ``key``, and its :class:`Layout`."""
    texels = texture.texels
    height, width = texels.shape[:2]
    if extension == "MIRROR":
        row = np.concatenate([texels, texels[:, ::-1]], axis=1)  # u' in [0, 1/2) reads the image itself
        out, layout = np.concatenate([row[::-1], row], axis=0), Layout((0.5, 0.5), (0.0, 0.0))  # so do v' (bottom)
    else:
        px, py = margin
        out = np.pad(texels, ((py, py), (px, px), (0, 0)), mode="edge" if extension == "EXTEND" else "constant")
        layout = Layout((width / (width + 2 * px), height / (height + 2 * py)),
                        (px / (width + 2 * px), py / (height + 2 * py)), margin)
    out = np.ascontiguousarray(out)
    out.flags.writeable = False
    return DecodedTexture(key, texture.header, out, texture.channels), layout
