"""The UV layout: every face drawn in texture space, flagged ones filled in the flag colour, the worst labelled.

The faces are drawn flat in one render (:func:`affinity.draw.flat.face_ids`),
uv taken as picture positions, so a layout of a million quads costs one pass.
Faces with the same uv quad (per-face unit squares, mirrored halves) are drawn
once, and their count is said; distinct quads together cover at most
``FRAGMENT_BUDGET`` pictures, so faces piled up in texture space cannot make the
pass cost a fragment per face per pixel. Edges are the pixels where the quad
changes. Faces too small to cover a pixel centre still mark the pixel under
their centroid, and flagged faces are drawn over the others where faces overlap
in uv, so no flagged face vanishes from the picture.
"""

from __future__ import annotations

from dataclasses import dataclass
from html import escape

import numpy as np

from ..mesh import Mesh
from .images import image_uri

FACE_FILL = np.array([0.86, 0.89, 0.93])
EDGE = np.array([0.42, 0.45, 0.50])
#: Side of the layout picture, pixels.
LAYOUT_SIZE = 640
#: Labelled faces per layout.
LABELLED = 8
#: The ring around a labelled face, the gap to its label, and the label's line height and (12 px
#: sans-serif) mean character width.
RING_RADIUS = 7
LABEL_GAP = 10
LABEL_LINE = 15
LABEL_CHAR_WIDTH = 6.8
FACES_PER_LINE = 4
#: The distinct uv quads drawn cover at most this many times the picture's pixels together (a layout whose
#: faces pile up in texture space would otherwise cost a fragment per face per pixel).
FRAGMENT_BUDGET = 24


def uv_bounds(uv: np.ndarray) -> tuple[np.ndarray, float]:
    """The square drawn: its lower-left corner (2,) and side, covering [0, 1]^2 and every coordinate."""
    low = np.minimum(np.nanmin(uv, axis=0), 0.0)
    high = np.maximum(np.nanmax(uv, axis=0), 1.0)
    return low, float((high - low).max())


@dataclass(frozen=True)
class Layout:
    """The layout picture and what it drew.

    image : (S, S, 3) float64 RGB
    low, side : (2,) lower-left corner and side of the uv square drawn (:func:`uv_bounds`)
    faces : mesh faces with uv at every corner
    quads : their render quads with uv at every corner (a triangle is one, an n-gon its fan)
    distinct : the distinct uv quads among them (quads with the same uv, to an eighth of a pixel, draw once)
    left_out : distinct quads not drawn, beyond :data:`FRAGMENT_BUDGET` (flagged ones are drawn first)
    """

    image: np.ndarray
    low: np.ndarray
    side: float
    faces: int
    quads: int
    distinct: int
    left_out: int


def _pixel_areas(points: np.ndarray, size: int) -> np.ndarray:
    """(R,) the shoelace area in pixels of quads ``points`` (R, 4, 2) in [-1, 1]^2."""
    x, y = points[..., 0], points[..., 1]
    twice = (x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y).sum(axis=1)
    return np.abs(twice) / 2 * (size / 2) ** 2


def layout_image(mesh: Mesh, flagged: np.ndarray, size: int) -> Layout | None:
    """The layout picture (see the module docstring); None without uv.

    ``flagged`` (F,) bool over the mesh's faces. Quads sharing their uv (per-face
    unit squares, mirrored halves) are drawn once, filled toward the flag colour by
    the share of them that is flagged; where distinct quads overlap, flagged ones
    are drawn over the others.
    """
    from ..draw import OVERLAY_TINT, face_ids, render_corners

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
    key = np.round(ndc * (4 * size)).astype(np.int64).reshape(len(ndc), 8)  # eighths of a pixel
    _, first, group = np.unique(key, axis=0, return_index=True, return_inverse=True)
    group = group.ravel()
    share = np.bincount(group, weights=flagged[faces], minlength=len(first)) / np.bincount(group)
    order = np.lexsort((first, share == 0))  # flagged first, then file order
    drawn = order[np.cumsum(_pixel_areas(ndc[first[order]], size)) <= FRAGMENT_BUDGET * size * size]
    drawn.sort()
    ids = face_ids(ndc[first[drawn]], share[drawn] > 0, size)
    covered = ids >= 0
    fill = FACE_FILL + share[drawn, None] * (OVERLAY_TINT - FACE_FILL)
    image = np.ones((size, size, 3))
    image[covered] = fill[ids[covered]]
    edge = np.zeros_like(covered)
    edge[:, :-1] |= ids[:, :-1] != ids[:, 1:]
    edge[:-1] |= ids[:-1] != ids[1:]
    image[edge] = EDGE
    centre = ndc[flagged[faces]].mean(axis=1)
    col = np.clip(((centre[:, 0] + 1) / 2 * size).astype(int), 0, size - 1)
    row = np.clip(((1 - centre[:, 1]) / 2 * size).astype(int), 0, size - 1)
    image[row, col] = OVERLAY_TINT
    return Layout(image, low, side, len(np.unique(faces)), len(faces), len(first), len(first) - len(drawn))


def face_uv_centre(mesh: Mesh, face: int) -> np.ndarray:
    """(2,) the mean uv of a face's corners."""
    corners = np.arange(mesh.face_start[face], mesh.face_start[face + 1])[None]
    return np.nanmean(mesh.corner_attribute("texcoords", corners)[0], axis=0)


def _label_lines(faces_by_code: dict[str, list[int]]) -> list[str]:
    """A ring's label, one line per rule and :data:`FACES_PER_LINE` faces: ``faces 3, 7 (Q101)``."""
    lines = []
    for code, faces in faces_by_code.items():
        for k in range(0, len(faces), FACES_PER_LINE):
            some = faces[k : k + FACES_PER_LINE]
            lines.append(f"face{'s' * (len(some) > 1)} {', '.join(map(str, some))} ({escape(code)})")
    return lines


def _free_baseline(baseline: float, left: float, width: float, boxes: list, size: int) -> float:
    """The first baseline at or below ``baseline`` (else above it) where a line ``left`` to ``left + width``
    covers none of ``boxes`` ((left, right, baseline) each) and stays inside the picture."""
    below = np.arange(baseline, size - 3, LABEL_LINE)
    above = np.arange(baseline - LABEL_LINE, 12, -LABEL_LINE)
    for candidate in (*below, *above):
        if not any(abs(candidate - b) < LABEL_LINE and left < right and start < left + width
                   for start, right, b in boxes):
            return float(candidate)
    return baseline


def layout_svg(mesh: Mesh, layout: Layout, labelled: list[tuple[int, str]]) -> str:
    """The layout as inline SVG: the picture of :func:`layout_image`, and a ringed label ``face F (CODE)`` at
    each labelled face.

    ``labelled`` is (face, rule code) of the worst places.
    Places whose uv centres fall within a ring of each other (e.g. every face
    mapped onto the whole texture) share one ring, labelled a line per rule
    (``faces 3, 7 (Q101)``); a line goes to the side of its ring with room,
    moved down (at the bottom, up) until it covers no other line and no ring.
    """
    image, low, side, size = layout.image, layout.low, layout.side, len(layout.image)
    rings: list[tuple[float, float, dict[str, list[int]]]] = []
    for face, code in labelled[:LABELLED]:
        u, v = (face_uv_centre(mesh, face) - low) / side
        x, y = u * size, (1 - v) * size
        same = next((ring for ring in rings if np.hypot(ring[0] - x, ring[1] - y) < 2 * RING_RADIUS), None)
        if same is None:
            rings.append(same := (x, y, {}))
        same[2].setdefault(code, []).append(face)
    marks = []
    boxes = [(x - RING_RADIUS, x + RING_RADIUS, y + 4) for x, y, _ in rings]  # a label covers no ring
    for x, y, faces_by_code in rings:
        marks.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{RING_RADIUS}" fill="none" stroke="#111827" '
                     f'stroke-width="2"/>')
        for text in _label_lines(faces_by_code):
            width = LABEL_CHAR_WIDTH * len(text)
            room_right, room_left = size - x - LABEL_GAP, x - LABEL_GAP
            anchor = "start" if width <= room_right or room_right >= room_left else "end"
            dx = LABEL_GAP if anchor == "start" else -LABEL_GAP
            left = x + dx if anchor == "start" else x + dx - width
            baseline = _free_baseline(y + 4, left, width, boxes, size)
            boxes.append((left, left + width, baseline))
            marks.append(f'<text x="{x + dx:.1f}" y="{baseline:.1f}" text-anchor="{anchor}" '
                         f'paint-order="stroke" stroke="#fff" stroke-width="3">{text}</text>')
    return (f'<svg class="uv-layout" role="img" aria-label="uv layout" width="{size}" height="{size}" '
            f'viewBox="0 0 {size} {size}" font-size="12" font-family="system-ui, sans-serif" fill="#111827">'
            f'<image href="{image_uri(image)}" width="{size}" height="{size}"/>'
            f'<rect width="{size}" height="{size}" fill="none" stroke="#9ca3af"/>{"".join(marks)}</svg>')
