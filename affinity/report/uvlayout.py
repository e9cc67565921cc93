"""The UV layout: every face drawn in texture space, flagged ones filled in the flag colour, the worst labelled.

The faces are rasterized with the project's own renderer, uv taken as screen
positions (an orthographic view of the texture square), so a layout of a
million quads costs one render. Edges are the pixels where the face changes.
Faces too small to cover a pixel centre still mark the pixel under their
centroid, and flagged faces are drawn over the others where faces overlap in uv,
so no flagged face vanishes from the picture.
"""

from __future__ import annotations

from html import escape

import numpy as np

from ..mesh import Mesh
from .images import image_uri

FACE_FILL = np.array([0.86, 0.89, 0.93])
EDGE = np.array([0.42, 0.45, 0.50])
#: Labelled faces per layout.
LABELLED = 8


def uv_bounds(uv: np.ndarray) -> tuple[np.ndarray, float]:
    """The square drawn: its lower-left corner (2,) and side, covering [0, 1]^2 and every coordinate."""
    low = np.minimum(np.nanmin(uv, axis=0), 0.0)
    high = np.maximum(np.nanmax(uv, axis=0), 1.0)
    return low, float((high - low).max())


def layout_image(mesh: Mesh, flagged: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray, float] | None:
    """(size, size, 3) float RGB of the layout, with the drawn square's corner and side; None without uv.

    ``flagged`` (F,) bool over the mesh's faces.
    """
    from render import rasterize_quads

    from ..draw.quads import render_corners
    from ..draw.shading import OVERLAY_TINT

    faces, corners = render_corners(mesh)
    uv = mesh.corner_attribute("texcoords", corners)
    if uv is None:
        return None
    keep = ~np.isnan(uv).any(axis=(1, 2))
    faces, uv = faces[keep], uv[keep]
    if len(faces) == 0:
        return None
    low, side = uv_bounds(uv.reshape(-1, 2))
    ndc = (uv - low) / side * 2.0 - 1.0
    # Flagged faces are nearer, so where faces overlap in uv (per-face unit squares, mirrored halves) they show.
    depth = np.repeat(np.where(flagged[faces], -0.5, 0.0)[:, None, None], 4, axis=1)
    clip = np.concatenate([ndc, depth, np.ones(ndc.shape[:2] + (1,))], axis=-1)
    frame = rasterize_quads(clip, np.zeros(ndc.shape[:2] + (1,)), size, size, method="split")
    face = np.where(frame.face >= 0, faces[np.maximum(frame.face, 0)], -1)
    image = np.ones((size, size, 3))
    image[face >= 0] = FACE_FILL
    image[(face >= 0) & flagged[np.maximum(face, 0)]] = OVERLAY_TINT
    edge = np.zeros_like(face, dtype=bool)
    edge[:, :-1] |= face[:, :-1] != face[:, 1:]
    edge[:-1] |= face[:-1] != face[1:]
    image[edge] = EDGE
    centre = ndc[flagged[faces]].mean(axis=1)
    col = np.clip(((centre[:, 0] + 1) / 2 * size).astype(int), 0, size - 1)
    row = np.clip(((1 - centre[:, 1]) / 2 * size).astype(int), 0, size - 1)
    image[row, col] = OVERLAY_TINT
    return image, low, side


def face_uv_centre(mesh: Mesh, face: int) -> np.ndarray:
    """(2,) the mean uv of a face's corners."""
    corners = np.arange(mesh.face_start[face], mesh.face_start[face + 1])[None]
    return np.nanmean(mesh.corner_attribute("texcoords", corners)[0], axis=0)


def layout_svg(mesh: Mesh, flagged: np.ndarray, labelled: list[tuple[int, str]], size: int = 640) -> str | None:
    """The layout as inline SVG: the raster picture, and a ringed label ``face F (CODE)`` at each labelled face.

    ``labelled`` is (face, rule code) of the worst places. None without uv.
    """
    drawn = layout_image(mesh, flagged, size)
    if drawn is None:
        return None
    image, low, side = drawn
    marks = []
    for face, code in labelled[:LABELLED]:
        u, v = (face_uv_centre(mesh, face) - low) / side
        x, y = u * size, (1 - v) * size
        anchor = "end" if x > size * 0.7 else "start"
        dx = -10 if anchor == "end" else 10
        marks.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="7" fill="none" stroke="#111827" stroke-width="2"/>'
                     f'<text x="{x + dx:.1f}" y="{y + 4:.1f}" text-anchor="{anchor}" paint-order="stroke" '
                     f'stroke="#fff" stroke-width="3">face {face} ({escape(code)})</text>')
    return (f'<svg class="uv-layout" role="img" aria-label="uv layout" width="{size}" height="{size}" '
            f'viewBox="0 0 {size} {size}" font-size="12" font-family="system-ui, sans-serif" fill="#111827">'
            f'<image href="{image_uri(image)}" width="{size}" height="{size}"/>'
            f'<rect width="{size}" height="{size}" fill="none" stroke="#9ca3af"/>{"".join(marks)}</svg>')
