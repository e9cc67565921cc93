"""Close-ups: a camera on a few faces of a mesh and the neighbourhood it needs to draw.

A close-up looks at a place (one or more neighbouring faces) from the side it is
seen from, from the distance that fits the place and its ring of neighbouring
faces in the picture. The side is chosen by visibility, never by the stored
winding alone: a few candidate directions (the mean normal and its opposite, each
tilted a little three ways) are drawn at low resolution with the depth test, and
the one where the place's own faces cover the most pixels wins (a left-handed
file, whose normals point inward, is seen from outside all the same). Only the
faces near the place are drawn (within a few radii, and nothing more than a radius
in front of it), so the place shows whether or not the rest of the mesh hides it
from the overview's camera.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..mesh import Mesh

#: Vertical field of view of a close-up, degrees.
CLOSEUP_FOV = 30.0
#: The view direction leans this far (degrees) off the mean normal, so relief and folds show.
TILT_DEGREES = 20.0
#: The ring of neighbours fills this fraction of the picture's half-height.
FILL = 0.85
#: Faces whose centroid is within this many ring radii of the place are drawn.
DRAWN_RADII = 2.5
#: Side of the visibility pre-pass that picks the view direction, pixels.
PREPASS_SIZE = 64
#: A ring reaching farther than this many place radii (long neighbours, a pole) is framed at that distance.
RING_RADII = 2.0


@dataclass(frozen=True)
class CloseupView:
    """Where a close-up's camera stands.

    camera : ``(eye, target, fov)`` as ``RenderOptions.camera`` takes it
    up : the world axis name (``"x"``, ``"y"``, ``"z"``) least aligned with the view direction
    drawn : (D,) int64, the mesh faces to draw (the place, its ring and what lies around them)
    ring : (N,) int64, the place's faces and every face sharing a vertex with them
    visible : the fraction of the pre-pass picture (``PREPASS_SIZE`` squared) the place's faces cover
    focus_visible : the fraction of it the focus faces cover (:func:`closeup_view`; the place's by default)
    """

    camera: tuple
    up: str
    drawn: np.ndarray
    ring: np.ndarray
    visible: float = 0.0
    focus_visible: float = 0.0


def face_vertices(mesh: Mesh, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The corners' vertices of ``faces``: (C,) int64 vertex per corner and (C,) int64 its face (from ``faces``)."""
    sizes = mesh.face_sizes[faces]
    owner = np.repeat(faces, sizes)
    starts = np.repeat(mesh.face_start[faces], sizes)
    offsets = np.arange(len(owner)) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    return mesh.corner_vertex[starts + offsets], owner


def ring_of(mesh: Mesh, faces: np.ndarray) -> np.ndarray:
    """(N,) int64 sorted: ``faces`` and every face that shares a vertex with one of them."""
    touched = np.zeros(len(mesh.positions), dtype=bool)
    touched[face_vertices(mesh, faces)[0]] = True
    every_vertex, owner = face_vertices(mesh, np.arange(mesh.n_faces))
    return np.unique(np.concatenate([faces, owner[touched[every_vertex]]]))


def face_centroids(mesh: Mesh) -> np.ndarray:
    """(F, 3) float64: the mean of each face's corner positions."""
    if mesh.n_faces == 0:
        return np.zeros((0, 3))
    total = np.add.reduceat(mesh.positions[mesh.corner_vertex], mesh.face_start[:-1], axis=0)  # faces are not empty
    return total / mesh.face_sizes[:, None]


def vector_areas(mesh: Mesh, faces: np.ndarray) -> np.ndarray:
    """(F, 3) float64: twice each polygon's vector area (Newell: sum of p_k x p_k+1 over its corners)."""
    vertices, _ = face_vertices(mesh, faces)
    p = mesh.positions[vertices]
    sizes = mesh.face_sizes[faces]
    first = np.repeat(np.cumsum(sizes) - sizes, sizes)
    following = np.arange(len(p)) + 1
    following = np.where(following - first >= np.repeat(sizes, sizes), first, following)  # wrap within the face
    total = np.zeros((len(faces), 3))
    np.add.at(total, np.repeat(np.arange(len(faces)), sizes), np.cross(p, p[following]))
    return total


def mean_normal(mesh: Mesh, faces: np.ndarray) -> np.ndarray:
    """(3,) unit area-weighted normal of ``faces`` (Newell's vector area of each polygon), or +z if they cancel."""
    area = vector_areas(mesh, faces).sum(axis=0)
    length = np.linalg.norm(area)
    return area / length if length > 0 else np.array([0.0, 0.0, 1.0])


def candidate_directions(normal: np.ndarray) -> np.ndarray:
    """(6, 3) unit view directions (target toward eye): ``normal`` (3,) and its opposite, each tilted by
    ``TILT_DEGREES`` toward the world axis least aligned with it, away from it, and across both.

    The first is the preferred one (toward the stored normal, tilted toward that axis): ties in
    visibility keep it, so a right-handed file's close-ups look as they always did.
    """
    side_axis = int(np.argmin(np.abs(normal)))
    side = np.eye(3)[side_axis] - normal * normal[side_axis]
    side /= np.linalg.norm(side)
    across = np.cross(normal, side)
    tilt = np.radians(TILT_DEGREES)
    directions = [np.cos(tilt) * facing + np.sin(tilt) * lean
                  for facing in (normal, -normal) for lean in (side, -side, across)]
    return np.array(directions)


@dataclass(frozen=True)
class _Surroundings:
    """What every view of one place shares: ``target`` (3,) the place's mean corner, ``radius`` its ring's
    reach from there (at most ``RING_RADII`` times the place's own), ``ring`` (N,) int64, and the faces
    ``near`` (K,) int64 whose centroid is within ``DRAWN_RADII`` radii, with their ``offset`` (K, 3) from
    the target."""

    target: np.ndarray
    radius: float
    ring: np.ndarray
    near: np.ndarray
    offset: np.ndarray


def _target_and_radius(mesh: Mesh, place: np.ndarray, ring: np.ndarray) -> tuple[np.ndarray, float]:
    """(3,) the mean corner of ``place`` (P,) int64, and its ``ring``'s (N,) int64 reach from there, at most
    ``RING_RADII`` times the place's own."""
    ring_points = mesh.positions[face_vertices(mesh, ring)[0]]
    place_points = mesh.positions[face_vertices(mesh, place)[0]]
    target = place_points.mean(axis=0)
    own = float(np.linalg.norm(place_points - target, axis=1).max())
    radius = min(float(np.linalg.norm(ring_points - target, axis=1).max()), RING_RADII * own)
    return target, (radius if radius > 0 else 1.0)


def frame_radius(mesh: Mesh, place: np.ndarray) -> float:
    """The world radius a close-up of ``place`` (P,) int64 frames (:func:`closeup_view`), without drawing."""
    return _target_and_radius(mesh, place, ring_of(mesh, place))[1]


def _surroundings(mesh: Mesh, place: np.ndarray, ring: np.ndarray) -> _Surroundings:
    """The :class:`_Surroundings` of ``place`` (P,) int64 and its ``ring`` (N,) int64."""
    target, radius = _target_and_radius(mesh, place, ring)
    offset = face_centroids(mesh) - target
    near = np.flatnonzero(np.einsum("fi,fi->f", offset, offset) <= (DRAWN_RADII * radius) ** 2)
    return _Surroundings(target, radius, ring, near, offset[near])


def _view_along(around: _Surroundings, direction: np.ndarray, aspect: float) -> CloseupView:
    """The close-up seen along unit ``direction`` (3,), framed on the place's ring."""
    half = np.radians(CLOSEUP_FOV) / 2
    narrow = min(half, np.arctan(np.tan(half) * aspect))
    eye = around.target + around.radius / (FILL * np.sin(narrow)) * direction
    up = "xyz"[int(np.argmin(np.abs(direction)))]
    # Draw what lies around the place, but nothing more than a radius in front of it: an occluder (an eyelid,
    # a helper cube inside the body, the other side of a thin part) would hide the place.
    drawn = np.union1d(around.near[around.offset @ direction <= around.radius], around.ring)
    return CloseupView((tuple(eye.tolist()), tuple(around.target.tolist()), CLOSEUP_FOV), up, drawn, around.ring)


def _nearest_faces(mesh: Mesh, view: CloseupView, width: int, height: int) -> np.ndarray:
    """(H, W) int64: the mesh face nearest the camera of ``view`` among ``view.drawn`` at each pixel, -1 where
    none (a depth-tested render)."""
    from .drawing import RenderOptions, render_mesh

    drawn = render_mesh(face_subset(mesh, view.drawn), RenderOptions(
        method="split", show="shaded", width=width, height=height, camera=view.camera, up=view.up))
    face = drawn.frame.face
    return np.where(face >= 0, view.drawn[drawn.faces[np.maximum(face, 0)]], -1)


def place_pixels(mesh: Mesh, view: CloseupView, place: np.ndarray, width: int, height: int) -> np.ndarray:
    """(H, W) bool: the pixels where ``place``'s faces are the nearest of ``view.drawn`` (a depth-tested render)."""
    return np.isin(_nearest_faces(mesh, view, width, height), place)


def closeup_view(mesh: Mesh, place: np.ndarray, aspect: float = 1.0, focus: np.ndarray | None = None,
                 focus_floor: float = 0.0) -> CloseupView:
    """Frame a camera on ``place`` (P,) int64 mesh faces from the side it is seen from.

    Each of :func:`candidate_directions` of the place's mean normal is drawn at
    ``PREPASS_SIZE`` pixels (:func:`place_pixels`). The direction where the place
    covers the most pixels wins, the first on a tie, among those where the ``focus``
    faces (F,) int64 (the place's worst face, say; default the place) cover at least
    ``focus_floor`` of the picture, when any does. The distance fits the bounding
    sphere of the place's ring (:func:`ring_of`), at most ``RING_RADII`` times the
    place's own, into ``FILL`` of the narrower half field of view.
    """
    focus = place if focus is None else focus
    around = _surroundings(mesh, place, ring_of(mesh, place))
    views = [_view_along(around, direction, aspect) for direction in candidate_directions(mean_normal(mesh, place))]
    height = max(1, round(PREPASS_SIZE / aspect))
    for k, view in enumerate(views):
        try:
            nearest = _nearest_faces(mesh, view, PREPASS_SIZE, height)
        except ValueError:  # everything is behind this camera: it sees nothing
            continue
        views[k] = replace(view, visible=float(np.isin(nearest, place).mean()),
                           focus_visible=float(np.isin(nearest, focus).mean()))
    # max keeps the first of equals
    return max(views, key=lambda view: (view.focus_visible >= focus_floor, view.visible))


def face_subset(mesh: Mesh, faces: np.ndarray) -> Mesh:
    """A mesh of ``faces`` (D,) int64 sorted, in that order, with the same vertex and attribute tables.

    Positions, uv, normals and colours keep their indices (unused entries stay),
    so attributes, seams and scores are unchanged; face ``i`` of the result is
    face ``faces[i]`` of ``mesh``.
    """
    sizes = mesh.face_sizes[faces]
    corners = np.repeat(mesh.face_start[faces], sizes) + (np.arange(sizes.sum())
                                                           - np.repeat(np.cumsum(sizes) - sizes, sizes))

    def take(array):
        return None if array is None else array[corners]

    return replace(
        mesh, face_start=np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
        corner_vertex=mesh.corner_vertex[corners], face_line=mesh.face_line[faces],
        corner_texcoord=take(mesh.corner_texcoord), corner_normal=take(mesh.corner_normal),
        face_group=mesh.face_group[faces], face_material=mesh.face_material[faces], prim_face_start=None,
    )


#: A place covering fewer pixels than this (about a 6 x 6 square) is a sliver (a folded or nearly collapsed quad):
#: its outline also grows outward, as a halo, so it can still be seen.
SLIVER_PIXELS = 32


def _shrunk(mask: np.ndarray, steps: int) -> np.ndarray:
    """``mask`` (H, W) bool eroded by ``steps`` pixels (4-neighbours; the image edge counts as outside)."""
    inside = mask.copy()
    for _ in range(steps):
        padded = np.pad(inside, 1, constant_values=False)
        inside = (inside & padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:])
    return inside


def outline(mask: np.ndarray, width: int = 2) -> np.ndarray:
    """(H, W) bool: the pixels of ``mask`` (H, W) bool within ``width`` pixels of its border.

    A pixel is on the border when one of its 4-neighbours (or the image edge) is
    outside the mask; the border then grows ``width - 1`` pixels inward. A mask
    of fewer than ``SLIVER_PIXELS`` pixels also gets a ``width``-pixel halo outside it.

    >>> mask = np.zeros((7, 7), bool); mask[3, 1:6] = True  # a 5-pixel sliver
    >>> int(outline(mask).sum()), int(mask.sum())
    (31, 5)
    """
    ring = mask & ~_shrunk(mask, width)
    if mask.sum() >= SLIVER_PIXELS:
        return ring
    grown = mask.copy()
    for _ in range(width):
        padded = np.pad(grown, 1, constant_values=False)
        grown = grown | padded[:-2, 1:-1] | padded[2:, 1:-1] | padded[1:-1, :-2] | padded[1:-1, 2:]
    return ring | grown
