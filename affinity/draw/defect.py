"""Where a flagged quad's crease is: the point where the split and the exact attribute differ most.

A close-up is framed on this point, at the defect's own scale (:func:`defect_camera`): the split (along the
diagonal the finding reads; :func:`turned_face` lets the renderer, which splits along 0-2, draw a 1-3 split)
against the quad's bilinear interpolation (Bloomenthal 2022, §2), sampled densely over the quad's parameters
(s, t) rather than taken from the closed form, so a quad off its plane or with a reflex corner is measured as
drawn. Through a decoded texture the point is where the two look most different instead.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

#: Samples per side of the (s, t) grid the crease is sought on (then again around the best one).
SAMPLES = 49
#: For uv, a close-up shows this many pixels per texel (a shift of k texels spans 8 k pixels) ...
PIXELS_PER_TEXEL = 8.0
#: ... but zooms in at most until the quad's diagonal 0-2 is this many panel widths long on screen.
DIAGONAL_PANELS = 2.0


@dataclass(frozen=True)
class Defect:
    """The crease of one quad.

    point : (3,) float64, the surface point P(s, t) where split and exact differ most (through the texture
        where one is given, :func:`quad_defect`)
    st : (2,) float64, its parameters
    shift : the largest difference, in the rule's unit (texels for uv, 1/255 for colours)
    texel : the world length of one texel there (sqrt of the area ratio; NaN without uv)
    diagonal : the world length of the quad's diagonal 0-2
    normal : (3,) float64 unit normal of the quad's best-fit plane
    bend : how far the corners lie off their best-fit plane, as a fraction of the longer diagonal
    folded : whether a corner is reflex or repeats (in the plane), where the finding's closed form is a bound
    across : whether this is the split along 1-3 (the corners taken from corner 1 on: :func:`turned_face`)
    """

    point: np.ndarray
    st: np.ndarray
    shift: float
    texel: float
    diagonal: float
    normal: np.ndarray
    bend: float = 0.0
    folded: bool = False
    across: bool = False


def _bilinear(corners: np.ndarray, s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(N, K) P(s, t) = (1-s)(1-t) c0 + s(1-t) c1 + s t c2 + (1-s) t c3 of ``corners`` (4, K) at (N,) s, t."""
    weights = np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t], axis=1)
    return weights @ corners


def split_attribute(plane: np.ndarray, attrs: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, K) the split's attribute at ``points`` (N, 2): barycentric in triangle (0, 1, 2) or (0, 2, 3) of the
    quad's in-plane corners ``plane`` (4, 2), whichever side of diagonal 0-2 the point lies on; ``attrs`` (4, K);
    and (N,) bool, whether the point lies in that triangle (a reflex corner's triangle leaves part of the quad
    uncovered: the split draws nothing there)."""
    def cross(a, b):
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]

    along = plane[2] - plane[0]
    side = np.sign(cross(along, points - plane[0]))
    # A point on the diagonal belongs to either triangle: take one with area (a repeated corner leaves one without)
    past_3 = (side == np.sign(cross(along, plane[3] - plane[0]))) & (side != 0)
    past_3 |= (side == 0) & (cross(along, plane[1] - plane[0]) == 0)
    other = np.where(past_3, 3, 1)[:, None]  # (N, 1) the third corner
    third = plane[other[:, 0]]
    area = cross(along, third - plane[0])
    area = np.where(np.abs(area) > 0, area, np.inf)  # no triangle: the point gets corner 0's value
    w2 = cross(points - plane[0], third - plane[0]) / area  # weight of corner 2
    w3 = cross(along, points - plane[0]) / area  # weight of the third corner
    w0 = 1 - w2 - w3
    inside = (np.minimum(np.minimum(w0, w2), w3) >= -1e-9) & np.isfinite(area)
    return w0[:, None] * attrs[0] + w2[:, None] * attrs[2] + w3[:, None] * attrs[other[:, 0]], inside


def quad_defect(corners: np.ndarray, attrs: np.ndarray, scale: np.ndarray, uv_texels: np.ndarray | None = None,
                image: np.ndarray | None = None) -> Defect:
    """The :class:`Defect` of one quad.

    Parameters
    ----------
    corners : (4, 3) float64 positions
    attrs : (4, K) float64 attribute at the corners (uv, colours)
    scale : (K,) float64, the attribute's unit per component (texture width, height for uv; 255 for colours)
    uv_texels : (4, 2) float64 uv in texels, for the texel's world length (None: NaN)
    image : (H, W, 3) the texture ``attrs`` (uv) read, or None. With it the point is where the two *look* most
        different (the texture sampled bilinearly through split and exact uv, the largest channel difference),
        since a large shift over a flat stretch of texture shows nothing; ``shift`` stays the quad's largest.

    The split's attribute at each sample is barycentric in its triangle of the quad's corners projected on
    the quad's best-fit plane; the exact one the bilinear P(s, t) (Bloomenthal 2022, eq. 1).
    """
    centre = corners.mean(axis=0)
    _, _, axes = np.linalg.svd(corners - centre)
    plane = (corners - centre) @ axes[:2].T  # (4, 2)

    def difference(s: np.ndarray, t: np.ndarray, through_image: bool = False) -> np.ndarray:
        exact = _bilinear(attrs, s, t)
        split, inside = split_attribute(plane, attrs, _bilinear(plane, s, t))
        if through_image:
            from ..textures.filtering import sample_bilinear

            apart = np.abs(sample_bilinear(image, split) - sample_bilinear(image, exact)).max(axis=1)
        else:
            apart = np.linalg.norm((split - exact) * scale, axis=1)
        return np.where(inside, apart, 0.0)

    st, shift = _largest(difference)
    if image is not None:
        seen_at, seen = _largest(lambda s, t: difference(s, t, True))
        st = seen_at if seen > 0 else st
    point = _bilinear(corners, st[:1], st[1:])[0]
    texel = np.nan
    if uv_texels is not None:
        uv_area = abs(_area(uv_texels))
        if uv_area > 0:
            texel = float(np.sqrt(abs(_area(plane)) / uv_area))
    lengths = np.linalg.norm(corners[[2, 3]] - corners[[0, 1]], axis=1)
    bend = float(np.ptp((corners - centre) @ axes[2]) / max(float(lengths.max()), 1e-300))
    edges = np.roll(plane, -1, axis=0) - plane
    turns = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
    folded = bool((np.sign(turns) != np.sign(_area(plane))).any())
    return Defect(point, st, shift, texel, float(lengths[0]), axes[2], bend, folded)


def _largest(measure) -> tuple[np.ndarray, float]:
    """(2,) (s, t) and the value of the largest of ``measure(s, t)`` ((N,) float64 of (N,) s and t) over a
    ``SAMPLES`` x ``SAMPLES`` grid of the unit square, then over as fine a grid again around its best sample."""
    step = 1.0 / (SAMPLES - 1)
    low, high = np.zeros(2), np.ones(2)
    for _ in range(2):
        s, t = (g.ravel() for g in np.meshgrid(np.linspace(low[0], high[0], SAMPLES),
                                               np.linspace(low[1], high[1], SAMPLES)))
        values = measure(s, t)
        k = int(np.argmax(values))
        low, high = np.maximum([s[k] - step, t[k] - step], 0), np.minimum([s[k] + step, t[k] + step], 1)
        step *= 2 / (SAMPLES - 1)
    return np.array([s[k], t[k]]), float(values[k])


def _area(polygon: np.ndarray) -> float:
    """The signed area of ``polygon`` (4, 2) (the shoelace formula)."""
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * float(x @ np.roll(y, -1) - y @ np.roll(x, -1))


def defect_camera(camera: tuple, defect: Defect, size: int) -> tuple[tuple, float]:
    """``camera`` ``(eye, target, fov)`` re-aimed at ``defect.point`` along the quad's normal (on the side the
    camera was), and its pixels per world unit at the target.

    Seen straight on, the split's triangles and the exact patch of a quad off its plane meet each pixel's ray at
    points that differ along the normal only, so the error map holds the shift without parallax.

    The distance gives ``PIXELS_PER_TEXEL`` pixels per texel where the quad has uv, but zooms in no further than
    a diagonal of ``DIAGONAL_PANELS`` panels (``size`` pixels) and zooms out no further than ``camera`` did.
    """
    eye, target, fov = camera
    direction = np.subtract(eye, target)
    current = float(np.linalg.norm(direction))
    direction = defect.normal if direction @ defect.normal >= 0 else -defect.normal
    span = 2 * np.tan(np.radians(fov) / 2)  # world height at distance 1

    def distance(pixels_per_unit: float) -> float:
        return size / (span * pixels_per_unit)

    nearest = distance(DIAGONAL_PANELS * size / defect.diagonal) if defect.diagonal > 0 else current
    wanted = distance(PIXELS_PER_TEXEL / defect.texel) if defect.texel > 0 else nearest
    far = min(current, max(wanted, nearest))
    eye = defect.point + far * direction
    return (tuple(eye.tolist()), tuple(defect.point.tolist()), fov), size / (span * far)


def face_defect(mesh, face: int, show: str, texture_size, diagonal: str = "02",
                image: np.ndarray | None = None) -> Defect | None:
    """The :class:`Defect` of ``mesh``'s quad ``face`` for the attribute ``show`` (``"uv"`` with the texture's
    ``texture_size`` (width, height) in texels, or ``"color"``); None for another face or attribute.

    ``diagonal`` is the check's setting: ``"02"``, ``"13"``, ``"shortest"`` (the shorter in 3-D) or ``"both"``
    (the one whose crease is larger, the one the finding reads); ``image`` (H, W, 3) the texture the uv reads, if
    it decodes (:func:`quad_defect`)."""
    if mesh.face_sizes[face] != 4:
        return None
    corners_at = np.arange(mesh.face_start[face], mesh.face_start[face] + 4)
    corners = mesh.positions[mesh.corner_vertex[corners_at]]
    if show == "uv" and mesh.texcoords is not None and (mesh.corner_texcoord[corners_at] >= 0).all():
        uv = mesh.texcoords[mesh.corner_texcoord[corners_at]]
        size = np.asarray(texture_size, dtype=np.float64)
        attrs, scale, uv_texels, look = uv, size, uv * size, image
    elif show == "color" and mesh.colors is not None:
        attrs, scale, uv_texels, look = mesh.colors[mesh.corner_vertex[corners_at]], np.full(3, 255.0), None, None
    else:
        return None
    turned = [1, 2, 3, 0]
    along = quad_defect(corners, attrs, scale, uv_texels, look)
    across = replace(quad_defect(corners[turned], attrs[turned], scale, None if uv_texels is None
                                 else uv_texels[turned], look), across=True)
    lengths = np.linalg.norm(corners[[2, 3]] - corners[[0, 1]], axis=1)
    pick = {"02": along, "13": across, "shortest": along if lengths[0] <= lengths[1] else across,
            "both": across if across.shift > along.shift else along}
    return pick.get(diagonal, along)


def turned_face(mesh, face: int):
    """``mesh`` with quad ``face``'s corners taken from its corner 1 on (1, 2, 3, 0): the same bilinear patch,
    whose split along 0-2 (the renderer's) is the original's split along 1-3."""
    start = mesh.face_start[face]
    order = np.arange(len(mesh.corner_vertex))
    order[start:start + 4] = order[[start + 1, start + 2, start + 3, start]]

    def take(array):
        return None if array is None else array[order]

    return replace(mesh, corner_vertex=mesh.corner_vertex[order], corner_texcoord=take(mesh.corner_texcoord),
                   corner_normal=take(mesh.corner_normal))
