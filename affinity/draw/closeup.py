"""A close-up of a flagged place: its framing, its panels (split | hybrid | exact) and the split's error map.

A close-up looks at a place (one or more neighbouring faces flagged by one rule) from the side it is seen
from, from the distance that fits the place and its ring of neighbouring faces in the picture. The side is
chosen by visibility, never by the stored winding alone: a few candidate directions (the mean normal and its
opposite, each tilted a little three ways) are drawn at low resolution with the depth test, and the one where
the place's own faces cover the most pixels wins (a left-handed file, whose normals point inward, is seen from
outside all the same). Only the faces near the place are drawn (within a few radii, and nothing more than a
radius in front of it), so the place shows whether or not the rest of the mesh hides it from the overview.

The panels draw what the rule is about (:func:`shown_for`). The texture is the mesh's own ``map_Kd`` when
it can be read; otherwise a procedural pattern of antialiased lines of constant u and v a few pixels apart on
screen (:func:`affinity.draw.texture.line_colours`), so the split's crease shows as lines kinking at the
diagonal whatever the atlas's scale. A rule whose finding is mirroring (``Rule.mirroring``, Q302) gets an
upright "F" drawn in uv over the lines (:func:`affinity.draw.texture.glyph_ink`): it reads mirrored on the
mirrored faces, which a symmetric pattern cannot show. A fold (``Rule.folding``) is drawn as the surface it
is: shaded by its own normals (the positions ride through the rasterizer as colours), lit across the fold,
with the split's diagonal. The error map is the split against exact in the attribute's unit; where the
crease is faint, a panel shows it amplified.

Every tuning constant of a close-up is below, in one place.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace

import numpy as np

from ..attributes import ATTRIBUTE_NAMES, ATTRIBUTES, drawn_attribute
from ..mesh import Mesh
from ..rules import RULES
from ..settings import Settings
from .faces import face_centroids, face_subset, face_vertices, mean_normal, ring_of, vector_areas

# -- Tuning: framing ------------------------------------------------------------------------------------------
#: Side of a close-up picture, pixels.
CLOSEUP_SIZE = 240
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
#: A close-up whose place covers fewer pixels than this fraction of the picture (300 pixels of 240 x 240) is
#: re-framed on its worst face, and dropped with a line saying why when that covers too few as well.
PLACE_FLOOR = 300 / 240**2
#: A place is framed whole when that frame is at most this many times as wide as its worst face's: a wider one
#: shrinks the worst face (and the kink of its lines at the split diagonal) below what an eye reads at page size,
#: so the close-up is framed on the worst face and its neighbours instead.
WHOLE_PLACE = 2.0
#: A place whose faces' area is below this fraction of its ring's is a sliver (a collapsed quad): it covers
#: no pixels from any side, so the floor does not apply and its outline's halo marks it.
SLIVER_AREA = 1e-3

# -- Tuning: panels -------------------------------------------------------------------------------------------
#: Methods of a close-up, left to right.
CLOSEUP_METHODS = ("split", "hybrid", "exact")
#: The 1-texel texture the line pattern replaces pixel by pixel.
PLAIN = np.ones((1, 1, 3), dtype=np.float32)
#: A face covering at least this many pixels of a close-up's split panel is seen in it: a later place whose
#: worst face an earlier close-up shows gets no close-up of its own (it would show the same spot again).
SEEN_PIXELS = 24
#: A place covering fewer pixels than this (about a 6 x 6 square) is a sliver (a folded or nearly collapsed quad):
#: its outline also grows outward, as a halo, so it can still be seen.
SLIVER_PIXELS = 32
#: The fold panel's light leans this far (degrees) from the eye toward the triangles' normals' difference.
LIGHT_LEAN = 50.0
#: Brightness of a surface facing away from the light, and of one facing it (a two-sided Lambert term).
AMBIENT, LIT = 0.12, 0.88
FOLD_SURFACE = np.array([0.86, 0.86, 0.84])
DIAGONAL_INK = np.array([0.05, 0.35, 0.85], dtype=np.float32)

# -- Tuning: error map ----------------------------------------------------------------------------------------
#: Shown attributes whose close-up also gets the split's difference from exact amplified, when it is faint (a
#: colour or normal crease of a few 1/255, a uv error under a pixel): the largest channel change is brought to
#: about ``COLOUR_REACH`` (of 1), the largest uv displacement to about ``UV_REACH`` pixels on screen, by a gain
#: of ``GAIN_STEPS`` times a power of ten.
AMPLIFIED = ("color", "normal")
COLOUR_REACH = 0.5
UV_REACH = 3.0
GAIN_STEPS = (1, 2, 5)
#: A colour or normal crease whose largest change on the place is below this (of 1) is under one 8-bit step: the
#: PNGs round it away, and amplified they show rounding noise, so the close-up has no amplified panel and says why.
EIGHT_BIT_STEP = 1 / 255
#: The difference panel draws |split - exact| times the gain (1, 2, 5 times a power of ten) that brings the
#: place's largest change to at most this (of 1).
DIFFERENCE_REACH = 1.0
#: Without a texture the lines are spaced at twice the shift (in texels), but at least ``LINE_SPACING`` and at
#: most this many pixels apart on screen, so a huge shift still leaves several lines crossing the panel.
WIDEST_LINES = 40.0
#: The error map's largest value on the place agrees with the finding's when within this fraction of it.
SCALE_AGREES = 0.1
#: ... unless its corners lie farther than this fraction of its diagonal off their plane (then the caption says
#: the error map holds parallax too).
BENT = 0.05


# -- Framing ---------------------------------------------------------------------------------------------------
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

    drawn = render_mesh(face_subset(mesh, view.drawn), RenderOptions(  # a split render: no routing settings read
        method="split", show="shaded", width=width, height=height, camera=view.camera, up=view.up,
        settings=Settings()))
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


def framed_view(mesh: Mesh, faces: np.ndarray, worst: int) -> tuple[CloseupView, np.ndarray]:
    """The view of a place of ``faces`` (P,) int64 whose worst face is ``worst``, and the faces it is framed on.

    The whole place when its frame is at most ``WHOLE_PLACE`` times as wide as its worst face's and, from the
    side that shows the worst face best, the place and its worst face each cover ``PLACE_FLOOR`` of the pre-pass
    (a close-up of a place whose worst face is hidden shows the wrong crease); else the worst face and its
    neighbours. When that covers less than the floor too (a sliver), the one of the two where the worst face is
    seen more, then the place.
    """
    worst = np.array([worst])
    if len(faces) == 1:
        return closeup_view(mesh, worst), worst

    def whole_view():  # the side that shows the worst face, if one does
        return closeup_view(mesh, faces, focus=worst, focus_floor=PLACE_FLOOR)

    whole = None
    if frame_radius(mesh, faces) <= WHOLE_PLACE * frame_radius(mesh, worst):
        whole = whole_view()
        if min(whole.visible, whole.focus_visible) >= PLACE_FLOOR:
            return whole, faces
    near = closeup_view(mesh, worst, focus=faces)
    if near.visible >= PLACE_FLOOR:
        return near, worst
    if whole is None:
        whole = whole_view()
    # The one that shows the worst face more, then the place (a sliver shows in neither)
    if (whole.focus_visible, whole.visible) > (near.visible, near.focus_visible):
        return whole, faces
    return near, worst



# -- Panels: a fold drawn as the surface it is ------------------------------------------------------------------
def triangle_normals(corners: np.ndarray) -> np.ndarray:
    """(Q, 2, 3) float64 unit normals of the split triangles (0, 1, 2) and (0, 2, 3) of quads ``corners``
    (Q, 4, 3); zero for a triangle without area."""
    from ..geometry import planar_quads

    # The doubled vector areas C_3, C_1 of the triangles opposite corners 3 and 1, as Q202 measures the fold.
    normals = np.transpose(planar_quads(corners).vector_areas[:, [3, 1]], (2, 1, 0))
    length = np.linalg.norm(normals, axis=-1, keepdims=True)
    return np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)


def fold_light(normals: np.ndarray, toward_eye: np.ndarray) -> np.ndarray:
    """(3,) unit light direction for one quad's split triangle ``normals`` (2, 3): ``toward_eye`` (3,) unit,
    leaned ``LIGHT_LEAN`` degrees toward the part of ``normals[0] - normals[1]`` across the view.

    Lambert's terms n_a . l and n_b . l then differ by sin(LIGHT_LEAN) |d| (d that part of the difference),
    while the light stays on the eye's side. Straight from the eye when the triangles agree."""
    difference = normals[0] - normals[1]
    across = difference - (difference @ toward_eye) * toward_eye
    length = np.linalg.norm(across)
    if not length > 1e-12:
        return toward_eye
    lean = np.radians(LIGHT_LEAN)
    return np.cos(lean) * toward_eye + np.sin(lean) * across / length


def surface_normals(points: np.ndarray, face: np.ndarray) -> np.ndarray:
    """(H, W, 3) float64 unit normals of a rendered surface from its points ``points`` (H, W, 3) (NaN where
    empty) and faces ``face`` (H, W) int (-1 where empty).

    The cross product of the points' steps along a row and down a column, each the forward step where the next
    pixel shows the same face, else the backward one; NaN where neither does. Its sign follows the screen, not
    the winding: shading is two-sided."""
    def step(axis: int) -> np.ndarray:
        forward = np.full(points.shape, np.nan)
        backward = np.full(points.shape, np.nan)
        ahead = [slice(None)] * 2
        behind = [slice(None)] * 2
        ahead[axis], behind[axis] = slice(1, None), slice(None, -1)
        ahead, behind = tuple(ahead), tuple(behind)
        difference = points[ahead] - points[behind]
        same = (face[ahead] == face[behind]) & (face[ahead] >= 0)
        forward[behind] = np.where(same[..., None], difference, np.nan)
        backward[ahead] = np.where(same[..., None], difference, np.nan)
        return np.where(np.isnan(forward), backward, forward)

    normal = np.cross(step(1), step(0))
    length = np.linalg.norm(normal, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return normal / length


def shade_fold(normals: np.ndarray, covered: np.ndarray, light: np.ndarray, background: np.ndarray) -> np.ndarray:
    """(H, W, 3) float32 RGB: ``FOLD_SURFACE`` lit by ``AMBIENT + LIT |n . l|`` where ``covered`` (H, W) bool
    (n from ``normals`` (H, W, 3), mid-grey where NaN), ``background`` (3,) elsewhere."""
    with np.errstate(invalid="ignore"):
        lambert = np.abs(normals @ light)
    brightness = AMBIENT + LIT * np.where(np.isnan(lambert), 0.5, lambert)
    image = np.where(covered[..., None], FOLD_SURFACE * brightness[..., None], background)
    return image.astype(np.float32)


def draw_diagonals(image: np.ndarray, face: np.ndarray, ends: np.ndarray, faces: np.ndarray,
                   matrix: np.ndarray) -> np.ndarray:
    """(H, W) bool: the pixels of ``image`` (H, W, 3), painted ``DIAGONAL_INK`` in place, where the segments
    ``ends`` (D, 2, 3) (each quad's corners 0 and 2, world space) cross their own face ``faces`` (D,) of
    ``face`` (H, W) int; ``matrix`` (4, 4) the camera's. Sampled at half-pixel steps along each segment."""
    from render import to_clip

    height, width = face.shape
    clip = to_clip(ends, matrix)  # (D, 2, 4)
    if not (clip[..., 3] > 0).all():
        keep = (clip[..., 3] > 0).all(axis=1)
        clip, faces = clip[keep], faces[keep]
    pixel = np.stack([(clip[..., 0] / clip[..., 3] + 1) * width / 2,
                      (1 - clip[..., 1] / clip[..., 3]) * height / 2], axis=-1)  # (D, 2, 2) x, y
    length = np.linalg.norm(pixel[:, 1] - pixel[:, 0], axis=-1)
    samples = np.maximum(np.ceil(2 * length).astype(np.int64), 1) + 1
    owner = np.repeat(np.arange(len(pixel)), samples)
    t = (np.arange(samples.sum()) - np.repeat(np.cumsum(samples) - samples, samples)) / np.repeat(samples - 1, samples)
    xy = pixel[owner, 0] + t[:, None] * (pixel[owner, 1] - pixel[owner, 0])
    column, row = np.floor(xy[:, 0]).astype(np.int64), np.floor(xy[:, 1]).astype(np.int64)
    inside = (column >= 0) & (column < width) & (row >= 0) & (row < height)
    row, column, owner = row[inside], column[inside], owner[inside]
    own = face[row, column] == faces[owner]
    drawn = np.zeros(face.shape, dtype=bool)
    drawn[row[own], column[own]] = True
    image[drawn] = DIAGONAL_INK
    return drawn


def positions_as_colours(mesh: Mesh) -> Mesh:
    """``mesh`` with its positions, moved and scaled alike on every axis into [0, 1], as its vertex colours: the
    rasterizer then interpolates the surface point of every pixel (flat on a split triangle, on the bilinear
    patch for exact), and a uniform scale keeps the directions of its normals."""
    used = mesh.positions[np.unique(mesh.corner_vertex)]
    low, extent = used.min(axis=0), float(np.ptp(used, axis=0).max())
    return replace(mesh, colors=np.clip((mesh.positions - low) / (extent if extent > 0 else 1.0), 0.0, 1.0))


# -- Panels: the place outlined ------------------------------------------------------------------------------
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


# -- Error map -------------------------------------------------------------------------------------------------
def gain_for(change: float, reach: float = COLOUR_REACH) -> float:
    """The gain (1, 2, 5, 10, 20, ...) that brings a largest ``change`` to at most ``reach``; 1 for a change
    already that big, or none."""
    if not change > 0:
        return 1.0
    wanted = reach / change
    decade = 10.0 ** np.floor(np.log10(max(wanted, 1.0)))
    return float(max([decade * step for step in GAIN_STEPS if decade * step <= wanted], default=decade))


def _amplified(split: np.ndarray, exact: np.ndarray, same: np.ndarray, unit: np.ndarray | float, reach: float,
               place: np.ndarray | None) -> tuple[np.ndarray, float]:
    """``exact + gain * (split - exact)`` (S, S, K) where ``same`` (S, S) bool, ``exact`` elsewhere, and the gain:
    :func:`gain_for` of the largest finite change in ``unit`` (a scalar, or (S, S, K) with NaN where unknown)
    on the place's pixels ``place`` (S, S) bool that ``same`` keeps (all of ``same``'s when none or None)."""
    error = np.where(same[..., None], split - exact, 0.0)
    gain = gain_for(largest_change(split, exact, same, place, unit), reach)
    return exact + gain * error, gain


def largest_change(split: np.ndarray, exact: np.ndarray, same: np.ndarray, place: np.ndarray | None,
                   unit: np.ndarray | float = 1.0) -> float:
    """The largest finite ``|split - exact|`` (S, S, K) in ``unit`` (a scalar, or (S, S, K) with NaN where
    unknown) on the place's pixels ``place`` (S, S) bool that ``same`` (S, S) bool keeps (all of ``same``'s
    when none or None); 0 where there are none."""
    keep = same if place is None or not (same & place).any() else same & place
    with np.errstate(invalid="ignore", divide="ignore"):
        change = (np.abs(split - exact) / unit)[keep]
    return float(change[np.isfinite(change)].max(initial=0.0))


def amplified_difference(split: np.ndarray, exact: np.ndarray, same: np.ndarray,
                         place: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """The split's picture with its difference from exact amplified: ``exact + gain * (split - exact)``.

    Parameters
    ----------
    split, exact : (S, S, 3) float RGB in [0, 1], the two close-ups
    same : (S, S) bool, the pixels where both show the same face (elsewhere the exact picture is kept:
        a silhouette is no crease)
    place : (S, S) bool, the place's pixels, whose largest change sets the gain (default: all ``same``)

    Returns
    -------
    (S, S, 3) float32 in [0, 1], and the gain (:func:`gain_for` of the largest change on the place).
    """
    image, gain = _amplified(split, exact, same, 1.0, COLOUR_REACH, place)
    return np.clip(image, 0.0, 1.0).astype(np.float32), gain


def amplified_uv(split: np.ndarray, exact: np.ndarray, same: np.ndarray, local: np.ndarray,
                 place: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """The split's texture coordinates with their error amplified: ``exact + gain * (split - exact)``.

    Parameters
    ----------
    split, exact : (S, S, 2) float uv of the two close-ups
    same : (S, S) bool, the pixels where both show the same face
    local : (S, S, 2) float, each pixel's footprint in u and v (NaN where unknown)
    place : (S, S) bool, the place's pixels, whose largest displacement sets the gain (default: all ``same``)

    Returns
    -------
    (S, S, 2) float64 uv (exact where not ``same``), and the gain that brings the place's largest
    displacement, in pixels of the pixel's own footprint, to about ``UV_REACH`` pixels.
    """
    return _amplified(split, exact, same, np.where(local > 0, local, np.nan), UV_REACH, place)


# -- The close-up -----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Closeup:
    """One close-up: the place, what is shown, the panels and the split's error against exact.

    place : what was drawn: the place (its ``code``, ``faces`` (P,) int64 and ``worst`` face)
    show : ``"uv"``, ``"color"``, ``"normal"``, ``"shaded"`` or ``"fold"`` (:func:`shown_for`)
    texture : what the panels are drawn with, in words
    framed : what the camera is framed on, in words
    images : method -> (S, S, 3) float RGB, the place outlined in the flag colour
    difference : (S, S, 3) float32, ``|split - exact|`` times ``difference_gain`` (None without an attribute)
    zoom : on-screen pixels per texel on the worst face's crease (uv), NaN where not measured
    crease : the caption's words on the crease framed: where, its shift, the zoom, the error map against the finding
    error : (S, S) float64 split error against exact in ``unit`` (None without an attribute or exact)
    covered : (S, S) bool, the pixels where split and exact show the same face
    own : (S, S) bool, the pixels where the split picture shows the place's faces
    view : the :class:`CloseupView` drawn (camera, up, drawn faces)
    seen : (K,) int64, the mesh faces covering at least ``SEEN_PIXELS`` pixels of the split picture
    amplified : (S, S, 3) float, the split with its difference from exact (colours, normals) or its uv error
        times ``gain``, where that is faint (a gain above 1), else None; ``amplified_label`` says which, and
        ``amplified_note`` why there is none where the difference is below one 8-bit step (``EIGHT_BIT_STEP``)
    dropped : why the close-up is not shown (its place covers too few pixels from every side), else None
    """

    place: object
    show: str
    texture: str
    framed: str
    images: dict = field(default_factory=dict)
    error: np.ndarray | None = None
    covered: np.ndarray | None = None
    own: np.ndarray | None = None
    unit: str = ""
    view: CloseupView | None = None
    dropped: str | None = None
    amplified: np.ndarray | None = None
    gain: float = 1.0
    amplified_label: str = ""
    amplified_note: str = ""
    seen: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    difference: np.ndarray | None = None
    difference_gain: float = 1.0
    zoom: float = float("nan")
    crease: str = ""

    @property
    def place_pixels(self) -> int:
        """The pixels the place's faces cover in the split picture (0 before it is drawn)."""
        return 0 if self.own is None else int(self.own.sum())


def shown_for(mesh: Mesh, code: str) -> str:
    """What a close-up of rule ``code``'s place draws: ``"fold"`` for a folding rule, a scored rule's attribute,
    else what a picture of the mesh draws (:func:`affinity.attributes.drawn_attribute`)."""
    rule = RULES[code]
    if rule.folding:
        return "fold"
    return ATTRIBUTE_NAMES[rule.attribute] if rule.scored else drawn_attribute(mesh)


@dataclass(frozen=True)
class _Paint:
    """How the panels are painted: ``show``, the ``image_file`` of the texture (None: none), ``lines`` (the line
    pattern replaces it), ``mirroring`` (with its glyphs) and ``label``, what that is in words."""

    show: str
    image_file: str | None
    lines: bool
    mirroring: bool
    label: str


def _paint(mesh: Mesh, code: str, texture: str | None, spacing: str | None = None) -> _Paint:
    """How a close-up of rule ``code``'s place on ``mesh`` is painted; ``texture`` is ``--texture``, overriding
    map_Kd; ``spacing`` says how far apart the lines are (default ``LINE_SPACING`` pixels)."""
    from ..textures.decode import why_not_decoded
    from .texture import GLYPH_SPACING, LINE_SPACING, painted_texture

    show = shown_for(mesh, code)
    path = painted_texture(mesh)
    refused = why_not_decoded(path) if path else None
    image_file = texture or (path if path and refused is None else None)  # map_Kd when the core decodes it
    lines = show == "uv" and not image_file
    mirroring = lines and RULES[code].mirroring
    if show == "uv" and image_file:
        label = f"texture {os.path.basename(image_file)}" + ("" if texture else " (map_Kd)")
    elif lines:
        label = f"lines of constant u (blue) and v (red) {spacing or f'{LINE_SPACING:g} pixels'} apart" + (
            f", and an upright F every {GLYPH_SPACING:g} pixels in uv: where it reads mirrored, so is the texture"
            if mirroring else "") + ("" if refused is None else f" (map_Kd {os.path.basename(path)} is not drawn: "
                                                                 f"{refused})")
    elif show == "fold":
        label = ("the surface shaded by its own normals, lit across the fold, with the split's diagonal (corners "
                 "0 to 2) in blue: the split draws two flat triangles meeting at it, exact the curved patch")
    else:
        label = {"color": "vertex colours", "normal": "normals as RGB", "shaded": "shading"}[show]
    return _Paint(show, image_file, lines, mirroring, label)


def _fold_picture(mesh: Mesh, faces: np.ndarray, worst: int, view: CloseupView, drawn,
                  sub_face: np.ndarray) -> np.ndarray:
    """(S, S, 3) float32: the fold panel of ``drawn`` (a render of :func:`positions_as_colours`), shaded by its
    surface's normals, lit across the ``worst`` face's fold (:func:`fold_light`), with the split diagonal of each
    quad of ``faces`` drawn (``sub_face`` (S, S) int: the face of ``view.drawn``)."""
    from .shading import BACKGROUND

    quads = faces[mesh.face_sizes[faces] == 4]
    corners = mesh.positions[face_vertices(mesh, quads)[0]].reshape(-1, 4, 3)
    eye, target, _ = view.camera
    toward_eye = np.subtract(eye, target) / np.linalg.norm(np.subtract(eye, target))
    k = int(np.flatnonzero(quads == worst)[0]) if worst in quads else 0
    light = fold_light(triangle_normals(corners[k:k + 1])[0], toward_eye) if len(quads) else toward_eye
    normals = surface_normals(drawn.frame.attrs, drawn.frame.face)
    image = shade_fold(normals, drawn.frame.face >= 0, light, BACKGROUND)
    draw_diagonals(image, sub_face, corners[:, [0, 2]], np.searchsorted(view.drawn, quads), drawn.camera.matrix)
    return image


@dataclass(frozen=True)
class _Panels:
    """The panels of a close-up: ``images`` method -> outlined picture, ``plain`` the same before the outline,
    ``frames`` method -> (render.Frame, (S, S) int face of ``view.drawn``), ``own`` and ``outline`` (S, S) bool
    (the place's pixels in the split panel and their outline), ``seen`` (K,) int64, ``footprint`` and
    ``glyphs`` the line pattern's scale (None without it)."""

    images: dict
    plain: dict
    frames: dict
    own: np.ndarray
    outline: np.ndarray
    seen: np.ndarray
    footprint: float | None
    glyphs: np.ndarray | None


def _panels(mesh: Mesh, faces: np.ndarray, worst: int, view: CloseupView, paint: _Paint, settings: Settings,
            size: int, pixel_tolerance: float, line_footprint: float | None = None) -> _Panels:
    """Split | hybrid | exact of ``view``, the place ``faces`` outlined; routed by ``settings``; the line pattern
    at ``line_footprint`` (uv per ``LINE_SPACING`` th of a line's spacing; None: the place's pixel footprint)."""
    from .drawing import RenderOptions, render_mesh
    from .shading import OVERLAY_TINT
    from .texture import glyph_footprints, line_colours, local_footprints, pixel_footprint

    sub = face_subset(mesh, view.drawn)
    in_place = np.isin(view.drawn, faces)
    fold = paint.show == "fold"
    images, plain, frames = {}, {}, {}
    own = edge_of_own = seen = glyphs = None
    footprint = line_footprint
    for method in CLOSEUP_METHODS:
        # With the line pattern, the render's own texture is replaced pixel by pixel: a 1-texel one costs nothing.
        # A fold's positions ride through the rasterizer as colours (scaled alike on every axis).
        options = RenderOptions(method=method, show="color" if fold else paint.show, width=size, height=size,
                                camera=view.camera, up=view.up, pixel_tolerance=pixel_tolerance, settings=settings,
                                texture=None if fold else PLAIN if paint.lines else paint.image_file)
        drawn = render_mesh(positions_as_colours(sub) if fold else sub, options)
        image = drawn.image.copy()
        face = drawn.frame.face
        covered = face >= 0
        sub_face = np.where(covered, drawn.faces[np.maximum(face, 0)], -1)
        place_pixels = covered & in_place[np.maximum(sub_face, 0)]
        if fold:
            image = _fold_picture(mesh, faces, worst, view, drawn, sub_face)
        edge = outline(place_pixels)
        if paint.lines:  # at the place's scale: the split's footprint on the place's pixels, for every panel
            footprint = footprint or pixel_footprint(drawn.frame.attrs, place_pixels)
            if paint.mirroring and glyphs is None:
                glyphs = glyph_footprints(drawn.frame.attrs, place_pixels, footprint)
            image[covered] = line_colours(drawn.frame.attrs[covered], footprint,
                                          local_footprints(drawn.frame.attrs)[covered], glyphs)
        if method == "split":
            own, edge_of_own = place_pixels, edge
            seen = view.drawn[np.bincount(sub_face[covered], minlength=len(view.drawn)) >= SEEN_PIXELS]
        plain[method] = image.copy()
        image[edge] = OVERLAY_TINT
        images[method] = image
        frames[method] = (drawn.frame, sub_face)
    return _Panels(images, plain, frames, own, edge_of_own, seen, footprint, glyphs)


@dataclass(frozen=True)
class _ErrorMap:
    """The split against exact: ``error`` (S, S) in ``unit`` where both show the same face (``covered``), and
    the amplified panel with its ``gain`` and ``label``, or the ``note`` saying why there is none."""

    error: np.ndarray | None = None
    covered: np.ndarray | None = None
    unit: str = ""
    amplified: np.ndarray | None = None
    gain: float = 1.0
    label: str = ""
    note: str = ""


def _texture_size(paint: _Paint, settings: Settings) -> tuple:
    """(width, height) in texels of the texture the panels draw, else the texture-size setting's square."""
    from ..loaders.imagesize import image_size

    return (image_size(paint.image_file) if paint.image_file else None) or (settings.texture_size,) * 2


def _error_map(panels: _Panels, paint: _Paint, settings: Settings) -> _ErrorMap:
    """The split's error against exact on the panels of an attribute (none for a fold or shading)."""
    from ..attributes import pixel_error
    from .shading import OVERLAY_TINT
    from .texture import line_colours, load_image, local_footprints, sample_bilinear

    attribute = next((a for a in ATTRIBUTES.values() if a.name == paint.show), None)
    if attribute is None or not {"split", "exact"} <= panels.frames.keys():
        return _ErrorMap()
    (split, split_face), (exact, exact_face) = panels.frames["split"], panels.frames["exact"]
    covered = (split_face >= 0) & (split_face == exact_face)
    texture_size = _texture_size(paint, settings)
    error = np.zeros(covered.shape)
    error[covered] = pixel_error(split.attrs[covered], exact.attrs[covered], attribute.field, texture_size)
    code = next(code for code, rule in RULES.items() if rule.scored and rule.attribute == attribute.field)
    unit = RULES[code].unit_for(settings.measure)
    note = ""
    if paint.show in AMPLIFIED:
        plain_split, plain_exact = panels.plain["split"], panels.plain["exact"]
        amplified, gain = amplified_difference(plain_split, plain_exact, covered, panels.own)
        what = "its difference from exact"
        change = largest_change(plain_split, plain_exact, covered, panels.own)
        if gain > 1 and change < EIGHT_BIT_STEP:
            note = (f"No amplified panel: split and exact differ by at most {change * 255:.2g}/255 on the place, "
                    "below one 8-bit step, so amplified it would show rounding noise.")
            gain = 1.0
    else:  # uv: the split's texture moved by gain times its error, drawn as the panels are
        local = local_footprints(exact.attrs)
        uv, gain = amplified_uv(split.attrs, exact.attrs, covered, local, panels.own)
        what = "its uv error"
        if gain > 1:
            amplified = panels.plain["exact"].copy()
            amplified[covered] = (line_colours(uv[covered], panels.footprint, local[covered], panels.glyphs)
                                  if paint.lines else sample_bilinear(load_image(paint.image_file), uv[covered]))
    if not gain > 1:  # at a gain of 1 the panel would be the split's again
        return _ErrorMap(error, covered, unit, note=note)
    amplified[panels.outline] = OVERLAY_TINT
    return _ErrorMap(error, covered, unit, amplified, gain, f"split, {what} ×{gain:g}")


def difference_panel(split: np.ndarray, exact: np.ndarray, same: np.ndarray,
                     place: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """(S, S, 3) float32 ``|split - exact| * gain`` in [0, 1] where ``same`` (S, S) bool, black elsewhere, of the
    panels ``split``, ``exact`` (S, S, 3) float RGB, and the gain (:func:`gain_for` of the largest change on the
    ``place`` (S, S) bool, at ``DIFFERENCE_REACH``)."""
    gain = gain_for(largest_change(split, exact, same, place), DIFFERENCE_REACH)
    image = np.where(same[..., None], np.abs(split - exact) * gain, 0.0)
    return np.clip(image, 0.0, 1.0).astype(np.float32), gain


def _area(mesh: Mesh, faces: np.ndarray) -> float:
    """The total area of ``faces`` (F,) int64."""
    return float(np.linalg.norm(vector_areas(mesh, faces), axis=1).sum() / 2)


def _zoom(panels: _Panels, texture_size: tuple, face: int) -> float:
    """On-screen pixels per texel on the pixels of ``face`` (an index into the drawn faces) in the exact panel:
    one over the median footprint of a pixel in texels (the mean of its u and v steps); NaN where none is
    measured."""
    from .texture import local_footprints

    frame, faces = panels.frames["exact"]
    steps = (local_footprints(frame.attrs) * np.asarray(texture_size, dtype=np.float64))[faces == face].mean(axis=-1)
    steps = steps[np.isfinite(steps) & (steps > 0)]
    return float(1 / np.median(steps)) if len(steps) else float("nan")


def _face_pixels(panels: _Panels, view: CloseupView, face: int) -> int:
    """The pixels mesh face ``face`` covers in the split panel of ``view``."""
    return int((panels.frames["split"][1] == np.searchsorted(view.drawn, face)).sum())


def _spaced_lines(mesh: Mesh, code: str, texture: str | None, shift: float, pixels_per_texel: float,
                  texture_size: tuple) -> tuple[_Paint, float]:
    """The line pattern spaced at twice the ``shift`` (texels), kept between ``LINE_SPACING`` and
    ``WIDEST_LINES`` pixels at ``pixels_per_texel``: its :class:`_Paint` and footprint (uv per sixth of a
    spacing, as :func:`affinity.draw.texture.line_colours` takes it)."""
    from .texture import LINE_SPACING

    texels = float(np.clip(2 * shift, LINE_SPACING / pixels_per_texel, WIDEST_LINES / pixels_per_texel))
    paint = _paint(mesh, code, texture, f"{texels:.3g} texels" + (" (twice the shift)" if texels == 2 * shift else ""))
    return paint, texels / float(np.sqrt(np.prod(texture_size))) / LINE_SPACING


def _scale_words(place, largest: float, unit: str, defect) -> str:
    """The caption's words on the error map's scale: the worst face's ``largest`` error in ``unit`` against the
    finding's shift (``place.shift`` where the finding reads C, else ``place.value``): within ``SCALE_AGREES``
    of it, or why not (``defect`` the quad's densely sampled crease)."""
    value = place.shift if np.isfinite(place.shift) else place.value
    said = f"The error map's largest on face {place.worst}, {largest:.3g} {unit}, "
    if abs(largest - value) <= SCALE_AGREES * value:
        return said + f"is within {SCALE_AGREES:.0%} of the finding's shift, {value:.3g} {unit}."
    if defect.folded:
        return said + (f"is off the finding's {value:.3g} {unit}: the quad has a reflex or repeated corner, where "
                       "the finding's closed form bounds the crease and the split draws one triangle outside the "
                       "quad or none.")
    if defect.bend > BENT:
        return said + (f"is off the finding's {value:.3g} {unit}: the quad bends {defect.bend:.0%} of its diagonal "
                       "off its plane, so on screen the split's triangles and the exact patch lie apart and the "
                       "error map adds their parallax to the shift.")
    return said + (f"is off the finding's {value:.3g} {unit}: the quad's crease, sampled densely, is "
                   f"{defect.shift:.3g} along the diagonal drawn.")


def closeup(mesh: Mesh, place, settings: Settings, size: int = CLOSEUP_SIZE, pixel_tolerance: float = 0.5,
            texture: str | None = None) -> Closeup:
    """Frame, draw and measure one ``place`` (its rule ``code``, ``faces`` (P,) int64 and ``worst`` face; see the
    module docstring), the hybrid routed by ``settings`` (the caller's, resolved once); ``texture`` is
    ``--texture``, overriding map_Kd.

    A uv or colour close-up is then re-aimed at the worst quad's crease (:func:`affinity.draw.defect.face_defect`)
    at the defect's scale (:func:`affinity.draw.defect.defect_camera`); without a texture its lines are spaced
    at twice the shift, so the kink at the diagonal is larger than the spacing."""
    from .defect import defect_camera, face_defect, turned_face
    from .texture import load_image

    view, framed_faces = framed_view(mesh, place.faces, place.worst)
    place_view = view
    paint = _paint(mesh, place.code, texture)
    texture_size = _texture_size(paint, settings)
    defect = (face_defect(mesh, place.worst, paint.show, texture_size, settings.diagonal,
                          load_image(paint.image_file) if paint.image_file and paint.show == "uv" else None)
              if RULES[place.code].scored else None)
    line_footprint = None
    drawn_mesh = mesh
    if defect is not None:
        camera, pixels_per_unit = defect_camera(view.camera, defect, size)
        view = replace(view, camera=camera, up="xyz"[int(np.argmin(np.abs(np.subtract(camera[0], camera[1]))))])
        if defect.across:  # the finding's crease is the split along 1-3: the renderer draws 0-2, so turn the quad
            drawn_mesh = turned_face(mesh, place.worst)
        pixels_per_texel = pixels_per_unit * defect.texel
        if paint.lines and defect.shift > 0 and pixels_per_texel > 0:
            paint, line_footprint = _spaced_lines(mesh, place.code, texture, defect.shift, pixels_per_texel,
                                                  texture_size)
    panels = _panels(drawn_mesh, place.faces, place.worst, view, paint, settings, size, pixel_tolerance,
                     line_footprint)
    if defect is not None and _face_pixels(panels, view, place.worst) < SLIVER_PIXELS:
        # Seen along its normal a sharply folded quad can hide itself: keep the framing on the place instead
        view, paint, defect = place_view, _paint(mesh, place.code, texture), None
        panels = _panels(mesh, place.faces, place.worst, view, paint, settings, size, pixel_tolerance)
    errors = _error_map(panels, paint, settings)
    place_pixels = int(panels.own.sum())
    sliver = _area(mesh, place.faces) < SLIVER_AREA * _area(mesh, view.ring)
    dropped = None
    if place_pixels < PLACE_FLOOR * size * size and not sliver:
        dropped = (f"{place.code} at face {place.worst}: its faces cover {place_pixels} pixels of the close-up "
                   f"from every side tried (fewer than {PLACE_FLOOR * size * size:.0f}), so it is not drawn")
    framed = ("the place's faces and their neighbours" if len(framed_faces) > 1
              else f"face {place.worst} and its neighbours")
    difference, difference_gain, zoom, crease = None, 1.0, float("nan"), ""
    if errors.error is not None:
        difference, difference_gain = difference_panel(panels.plain["split"], panels.plain["exact"],
                                                       errors.covered, panels.own)
    if defect is not None:
        crease = (f"Centred on the point of face {place.worst} where split and exact differ most "
                  f"({defect.shift:.3g} {errors.unit}, the split along {'1-3' if defect.across else '0-2'})")
        if paint.show == "uv":
            zoom = _zoom(panels, texture_size, int(np.searchsorted(view.drawn, place.worst)))
            crease += f", 1 texel = {zoom:.2g} px"
        # the worst face's pixels but its edge, where a pixel of one face's split meets the other's patch
        worst = errors.covered & _shrunk(panels.frames["split"][1] == np.searchsorted(view.drawn, place.worst), 1)
        if errors.error is not None and worst.any():
            crease += ". " + _scale_words(place, float(errors.error[worst].max()), errors.unit, defect)
    return Closeup(place=place, show=paint.show, texture=paint.label, framed=framed, images=panels.images,
                   error=errors.error, covered=errors.covered, own=panels.own, unit=errors.unit, view=view,
                   dropped=dropped, amplified=errors.amplified, gain=errors.gain, amplified_label=errors.label,
                   amplified_note=errors.note, seen=panels.seen, difference=difference,
                   difference_gain=difference_gain, zoom=zoom, crease=crease)
