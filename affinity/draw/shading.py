"""Shading: the attributes a render needs per corner, and the colour of every covered pixel.

Also the palette every picture of the project shares: the background and the
tint that marks flagged quads (``FLAG_COLOUR`` as a CSS colour).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..mesh import Mesh

BACKGROUND = np.array([1.0, 1.0, 1.0], dtype=np.float32)
OVERLAY_TINT = np.array([1.0, 0.1, 0.6], dtype=np.float32)
#: Flagged quads are drawn in the overlay's tint everywhere: renders, report charts, the 3-D view.
FLAG_COLOUR = "#" + "".join(f"{round(c * 255):02x}" for c in OVERLAY_TINT)


def flat_normals(positions: np.ndarray) -> np.ndarray:
    """Unit normal of each quad's own plane (``affinity.geometry.quad_normals``), repeated per corner.

    (R, 4, 3) -> (R, 4, 3); zero for a quad whose corners are collinear.
    """
    from ..geometry import quad_normals

    n = quad_normals(positions)
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    n = np.divide(n, length, out=np.zeros_like(n), where=length > 0)
    return np.repeat(n[:, None], 4, axis=1)


@dataclass
class ShadingInputs:
    """Per-corner attributes handed to the rasterizer and how to read them back.

    ``attrs`` is (R, 4, K): uv in columns ``uv`` (a slice or None), colours in
    ``color``, normals in ``normal``.
    """

    attrs: np.ndarray
    uv: slice | None
    color: slice | None
    normal: slice | None


def shading_inputs(mesh: Mesh, corners: np.ndarray, show: str) -> ShadingInputs:
    """Gather the attributes ``show`` needs; missing ones fall back (checker needs uv).

    Raises ValueError when the mesh lacks what ``show`` needs and there is no fallback.
    """
    columns: list[np.ndarray] = []
    slices: dict[str, slice | None] = {"uv": None, "color": None, "normal": None}

    def add(name: str, values: np.ndarray) -> None:
        start = sum(c.shape[-1] for c in columns)
        columns.append(np.nan_to_num(values))
        slices[name] = slice(start, start + values.shape[-1])

    uv = mesh.corner_attribute("texcoords", corners)
    if show in ("uv", "shaded") and uv is not None:
        add("uv", uv)
    if show == "uv" and uv is None:
        raise ValueError("the mesh has no texture coordinates (try --show shaded or --show color)")
    if show == "color":
        colors = mesh.corner_attribute("colors", corners)
        if colors is None:
            raise ValueError("the mesh has no vertex colours (try --show shaded)")
        add("color", colors)
    if show in ("normal", "shaded"):
        normals = mesh.corner_attribute("normals", corners)
        positions = mesh.corner_attribute("positions", corners)
        fallback = flat_normals(positions)
        add("normal", fallback if normals is None else np.where(np.isnan(normals), fallback, normals))
    return ShadingInputs(np.concatenate(columns, axis=-1), **slices)


def shade(attrs: np.ndarray, covered: np.ndarray, inputs: ShadingInputs, show: str,
          texture: np.ndarray | None, light: np.ndarray) -> np.ndarray:
    """Colour every covered pixel from its interpolated attributes.

    ``uv`` shows the texture (trilinear mip-mapped by each pixel's footprint, so minified patterns do not alias
    into moire: :func:`affinity.draw.texture.sample_mipmapped`), ``color`` the vertex colours, ``normal`` the unit
    normal as RGB, ``shaded`` the texture (or grey without uv) lit by a
    two-sided Lambert term.

    Parameters
    ----------
    attrs : (H, W, K) float, the rasterizer's interpolated attributes
    covered : (H, W) bool
    show : "uv", "color", "normal" or "shaded"
    texture : (h, w, 3) float32, sampled where ``inputs.uv`` is set
    light : (3,) unit vector toward the light

    Returns
    -------
    (H, W, 3) float32 RGB in [0, 1], background where not covered.
    """
    from .texture import local_footprints, sample_mipmapped

    values = attrs[covered]
    if show == "color":
        colour = values[:, inputs.color]
    elif inputs.uv is not None:
        footprint = local_footprints(attrs[..., inputs.uv])[covered]
        colour = sample_mipmapped(texture, values[:, inputs.uv], footprint)
    else:
        colour = np.full((len(values), 3), 0.8)
    if show in ("normal", "shaded"):
        n = values[:, inputs.normal]
        n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
        colour = 0.5 * (n + 1.0) if show == "normal" else colour * (0.15 + 0.85 * np.abs(n @ light))[:, None]
    image = np.broadcast_to(BACKGROUND, covered.shape + (3,)).copy()
    image[covered] = np.clip(colour, 0.0, 1.0)
    return image
