"""Quad shape: each quad in its own plane, and the shape measures of rules Q201-Q204, Q301-Q302.

Every function is vectorized over Q quads whose corners come in face order,
``corners`` (Q, 4, D) float64 with D = 3 (positions) or D = 2 (texture
coordinates). Tolerances are relative to the quad's size (its longest edge),
never absolute, so a millimetre asset and a kilometre terrain are judged alike.

The central quantities are the four triangle areas

    T_i = 2 * signed area of the triangle (p_{i+1}, p_{i+2}, p_{i+3})   (indices mod 4),

the triangle opposite corner i, in the quad's own plane (counter-clockwise
positive around the plane normal). They are also the corner turns: the turn at
corner k, cross(p_k - p_{k-1}, p_{k+1} - p_k), is T_{k+2}. T_0 + T_2 = T_1 + T_3
is twice the quad's signed area. The affinity test (``affinity.measures``) and the
shape rules here are all read off them.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

#: A triangle or quad whose area is at most this fraction of the square of its
#: quad's longest edge counts as degenerate (its barycentric coordinates are not
#: used). The same figure is rule Q201's default threshold.
DEGENERATE_AREA = 1e-9

#: Doubled areas up to ROUNDING_AREA * eps * |largest coordinate| * longest edge are
#: within rounding of zero: coordinates of magnitude |p| carry an error of eps |p| / 2
#: each, which moves a doubled triangle area (a cross product of two edges) by up
#: to about 2 sqrt(3) eps |p| times the edge length; twice that is the margin. A
#: unit quad offset by 1e9 has a rounding area of about 4e-6, far above the
#: relative tolerance above.
ROUNDING_AREA = 8.0


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(..., D), (..., D) -> (...) dot products."""
    return np.einsum("...d,...d->...", a, b)


def lengths(vectors: np.ndarray) -> np.ndarray:
    """(..., D) -> (...) Euclidean lengths (faster than ``np.linalg.norm`` on short vectors)."""
    return np.sqrt(_dot(vectors, vectors))


def _unit(vectors: np.ndarray) -> np.ndarray:
    """(..., D) vectors scaled to length 1; zero vectors stay zero."""
    length = lengths(vectors)[..., None]
    return np.divide(vectors, length, out=np.zeros_like(vectors), where=length > 0)


def _corner_major(corners: np.ndarray) -> np.ndarray:
    """(Q, 4, D) -> (4, Q, D) copy, so that each corner p_k is one contiguous block and
    combining corners streams through memory."""
    return np.ascontiguousarray(np.moveaxis(corners, 1, 0))


def by_component(corners: np.ndarray) -> np.ndarray:
    """(Q, 4, D) corners -> (D, 4, Q) float64 copy: component d of corner k of every
    quad is one contiguous row, the layout the measures compute in."""
    return np.ascontiguousarray(np.transpose(np.asarray(corners, dtype=np.float64), (2, 1, 0)))


#: C_{k-2}, the corner turn at corner k, for k = 0..3 (component-major; see :func:`_opposite_areas`).
_CORNER_TURN_AT = [2, 3, 0, 1]


def _orthonormal_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors e1, e2 (Q, 3) with e1 x e2 = normal, for unit normals (Q, 3).

    Branchless construction of Duff et al., "Building an Orthonormal Basis,
    Revisited", JCGT 6(1), 2017 (Listing 3). A zero normal gets e1 = x, e2 = y.
    """
    x, y, z = normal.T
    sign = np.copysign(1.0, z)
    a = -1.0 / (sign + z)
    b = x * y * a
    e1 = np.stack([1.0 + sign * x * x * a, sign * b, -sign * x], axis=1)
    e2 = np.stack([b, sign + y * y * a, -y], axis=1)
    return e1, e2


def _in_plane(p: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(4, Q, 2) in-plane coordinates of 3-D corners ``p`` (4, Q, 3) in the planes of unit ``normals``
    (Q, 3); see ``plane_coordinates``."""
    e1, e2 = _orthonormal_basis(normals)
    # Offsets from corner 0 first, so coordinates far from the origin keep their digits.
    offsets = p - p[0]
    xy = np.stack([_dot(offsets, e1), _dot(offsets, e2)], axis=2)
    xy -= xy.mean(axis=0)
    return xy


def quad_normals(corners: np.ndarray) -> np.ndarray:
    """Normals of the quads' own planes, following the face winding (right-hand rule).

    The normal is the cross product of the diagonals, n = (p2 - p0) x (p3 - p1),
    twice the quad's vector area (design.md). Where the diagonals are parallel (a
    symmetric bow-tie, whose two lobes cancel, or a collapsed diagonal) the
    largest corner normal (p_k - p_{k-1}) x (p_{k+1} - p_k) stands in; it is zero
    only when all four corners are collinear.

    Parameters
    ----------
    corners : (Q, 4, 3) float64

    Returns
    -------
    (Q, 3) float64, not normalized.
    """
    return planar_quads(corners).plane_normals.T


def plane_coordinates(corners: np.ndarray) -> np.ndarray:
    """Project each quad onto its own plane: the plane through the centroid of its
    corners with normal ``quad_normals(corners)``.

    This replaces Listing 3's area sign taken from ``v.z`` (Bloomenthal 2022),
    which is wrong for quads facing sideways: the in-plane basis (e1, e2) is
    orthonormal with e1 x e2 = n / |n|, so 2-D signed areas are the 3-D vector
    areas measured along the quad's own normal.

    Parameters
    ----------
    corners : (Q, 4, 3) float64

    Returns
    -------
    (Q, 4, 2) float64 in-plane coordinates, centroid at the origin; lengths and
    angles are preserved for planar quads.
    """
    return planar_quads(corners).xy


# Component-major helpers: ``p`` is (D, 4, Q), p[d, k] component d of corner k.


def _edges(p: np.ndarray) -> np.ndarray:
    """(D, 6, Q) edge vectors e_k = p_{k+1} - p_k at [:, k], k = 0..5 (indices mod 4): the
    four edges followed by e_0, e_1 again, so that every run of consecutive edges is a slice."""
    e = np.empty((p.shape[0], 6, p.shape[2]))
    np.subtract(p[:, 1:], p[:, :-1], out=e[:, :3])
    np.subtract(p[:, 0], p[:, -1], out=e[:, 3])
    e[:, 4:] = e[:, :2]
    return e


def squared_lengths(v: np.ndarray) -> np.ndarray:
    """(D, ...) vectors laid out by component -> (...) squared Euclidean lengths."""
    return dot_by_component(v, v)


def dot_by_component(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(D, ...), (D, ...) vectors laid out by component -> (...) float64 dot products
    (broadcast against each other)."""
    return np.einsum("d...,d...->...", a, b)


def cross_by_component(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(3, ...) cross products a x b of vectors laid out by component (3, ...) float64
    (``np.cross(a, b, axis=0)`` without its axis moves and copies)."""
    out = np.empty_like(a)
    for d in range(3):
        u, v = (d + 1) % 3, (d + 2) % 3
        np.multiply(a[u], b[v], out=out[d])
        out[d] -= a[v] * b[u]
    return out


def _opposite_areas(e: np.ndarray) -> np.ndarray:
    """(D, 6, Q) edges (see :func:`_edges`) -> C_i = e_{i+1} x e_{i+2}, the doubled vector
    area of the triangle opposite corner i (the corner turn at corner i + 2): (3, 4, Q)
    vectors for D = 3, (4, Q) z components for D = 2."""
    following, after = e[:, 1:5], e[:, 2:6]
    if len(e) == 2:
        C = following[0] * after[1]
        C -= following[1] * after[0]
        return C
    return cross_by_component(following, after)


@dataclass(frozen=True)
class PlanarQuads:
    """Quads seen in their own planes, with what the measures share.

    Attributes
    ----------
    areas : (Q, 4) float64
        T_i, twice the signed area of the triangle (p_{i+1}, p_{i+2}, p_{i+3})
        opposite corner i, counter-clockwise positive: in the quad's plane,
        T_i = (e_{i+1} x e_{i+2}) . n / |n| with edges e_k = p_{k+1} - p_k (the
        area of the triangle projected onto the plane), or the 2-D cross
        product for 2-D corners.
    size : (Q,) float64
        Longest edge, measured on the original corners.
    diagonals : (Q, 2) float64
        Lengths of the diagonals 0-2 and 1-3, measured on the original corners.
    components : (D, 4, Q) float64
        The corners themselves (see :func:`by_component`).
    normals : (3, Q) float64 or None
        The quad normals d02 x d13 of 3-D corners (before the stand-in for
        parallel diagonals, see :func:`quad_normals`); None for 2-D corners.
    vector_areas : (3, 4, Q) float64 or None
        C_i = e_{i+1} x e_{i+2}, the doubled vector area of the triangle opposite
        corner i, of 3-D corners (so T_i = C_i . n / |n|); None for 2-D corners.
    epsilon : float
        The machine epsilon of the corners as the file stored them (float32's for a USD
        ``point3f[]``): :attr:`rounding` scales with it.
    """

    areas: NDArray[np.float64]
    size: NDArray[np.float64]
    diagonals: NDArray[np.float64]
    components: NDArray[np.float64]
    normals: NDArray[np.float64] | None = None
    vector_areas: NDArray[np.float64] | None = None
    epsilon: float = float(np.finfo(np.float64).eps)

    @cached_property
    def xy(self) -> np.ndarray:
        """(Q, 4, 2) float64 in-plane corners: ``plane_coordinates`` of 3-D corners,
        2-D corners as they are."""
        corners = np.transpose(self.components, (2, 1, 0))
        if len(self.components) == 2:
            return corners
        return np.moveaxis(_in_plane(_corner_major(corners), _unit(self.plane_normals.T)), 0, 1)

    @cached_property
    def plane_normals(self) -> np.ndarray | None:
        """(3, Q) float64 normals of the quads' own planes (:func:`quad_normals`): :attr:`normals`, the
        largest corner normal standing in where the diagonals are parallel; None for 2-D corners."""
        if self.normals is None:
            return None
        return _with_stand_ins(self.vector_areas, self.normals, self.diagonals)

    @cached_property
    def valid(self) -> np.ndarray:
        """(Q, 4) bool: the triangle opposite corner i is not degenerate
        (its area exceeds ``DEGENERATE_AREA`` times the squared longest edge)."""
        return np.abs(self.areas) > self.tolerance[:, None]

    @cached_property
    def tolerance(self) -> np.ndarray:
        """(Q,) float64: the largest T_i (twice an area) that counts as zero: the larger of
        the relative tolerance 2 ``DEGENERATE_AREA`` size^2 and the :attr:`rounding` area."""
        return np.maximum(2 * DEGENERATE_AREA * self.size**2, self.rounding)

    @cached_property
    def reflex(self) -> np.ndarray:
        """(Q, 4) bool: corner turns T_i that go clockwise, beyond the degenerate :attr:`tolerance`."""
        return self.areas < -self.tolerance[:, None]

    @cached_property
    def rounding(self) -> np.ndarray:
        """(Q,) float64: doubled areas within rounding of zero for corners of this
        magnitude, ``ROUNDING_AREA`` eps max_k |p_k| times the longest edge: eps float64's, and the
        :attr:`epsilon` of the stored corners for a quad all of whose T_i lie within that (a float32 sliver
        whose corners are collinear up to float32 rounding is degenerate, Q201, not a bow-tie)."""
        magnitude = np.maximum(self.components.max(axis=(0, 1)), -self.components.min(axis=(0, 1)))
        computed = (ROUNDING_AREA * np.finfo(np.float64).eps) * magnitude * self.size
        if self.epsilon <= np.finfo(np.float64).eps:
            return computed
        stored = (ROUNDING_AREA * self.epsilon) * magnitude * self.size
        return np.where(np.abs(self.areas).max(axis=1, initial=0.0) <= stored, stored, computed)

    def take(self, rows) -> PlanarQuads:
        """The quads selected by ``rows`` (an index array, a boolean mask or a slice)."""
        if isinstance(rows, slice) and rows == slice(None):
            return self
        normals = None if self.normals is None else self.normals[:, rows]
        vector_areas = None if self.vector_areas is None else self.vector_areas[:, :, rows]
        return PlanarQuads(self.areas.T[:, rows].T, self.size[rows], self.diagonals[rows], self.components[:, :, rows],
                           normals, vector_areas, self.epsilon)

    def __len__(self) -> int:
        return len(self.size)


def planar_quads(corners: np.ndarray) -> PlanarQuads:
    """Build :class:`PlanarQuads` from 3-D corners (seen in the plane of
    ``plane_coordinates``) or 2-D corners (texture coordinates, used as they are).

    Parameters
    ----------
    corners : (Q, 4, 3) or (Q, 4, 2) float64
    """
    return planar_quads_by_component(by_component(corners))


def planar_quads_by_component(p: np.ndarray, epsilon: float = float(np.finfo(np.float64).eps)) -> PlanarQuads:
    """:func:`planar_quads` of corners laid out by component.

    Parameters
    ----------
    p : (D, 4, Q) float64, D = 3 or 2 (see :func:`by_component`)
    epsilon : the machine epsilon of the corners as stored (:attr:`PlanarQuads.epsilon`)
    """
    e = _edges(p)
    size = np.sqrt(squared_lengths(e[:, :4]).max(axis=0))
    C = _opposite_areas(e)
    d02, d13 = e[:, 0] + e[:, 1], e[:, 1] + e[:, 2]
    diagonals = np.empty((len(size), 2))
    diagonals[:, 0], diagonals[:, 1] = squared_lengths(d02), squared_lengths(d13)
    np.sqrt(diagonals, out=diagonals)
    if len(p) == 2:
        return PlanarQuads(C.T, size, diagonals, p, epsilon=epsilon)
    # d02 x d13 = c_0 + c_2 (c_k = C_{k-1} the corner turns): twice the vector area.
    normals = C[:, 3] + C[:, 1]
    plane = _with_stand_ins(C, normals, diagonals)
    plane_length = np.sqrt(squared_lengths(plane))
    # T_i = C_i . n / |n|; a zero normal (all corners collinear) leaves T_i = C_i . n = 0.
    areas = dot_by_component(C, plane[:, None])
    np.divide(areas, plane_length, out=areas, where=plane_length > 0)
    return PlanarQuads(areas.T, size, diagonals, p, normals, C, epsilon)


def _with_stand_ins(C: np.ndarray, normals: np.ndarray, diagonals: np.ndarray) -> np.ndarray:
    """(3, Q) float64 plane normals: ``normals`` (3, Q), d02 x d13, where the diagonals (lengths (Q, 2)) are
    not parallel; where they are (|d02 x d13| <= DEGENERATE_AREA |d02| |d13|: a symmetric bow-tie, a
    collapsed diagonal) the largest corner normal C_{k-2} of the vector areas C (3, 4, Q) stands in.
    ``normals`` itself when no quad needs a stand-in, else a new array."""
    parallel = np.flatnonzero(np.sqrt(squared_lengths(normals)) <= DEGENERATE_AREA * diagonals[:, 0] * diagonals[:, 1])
    if not len(parallel):
        return normals
    corner = C[:, _CORNER_TURN_AT][:, :, parallel]  # the normal at corner k is C_{k-2}
    largest = squared_lengths(corner).argmax(axis=0)
    plane = normals.copy()
    plane[:, parallel] = corner[:, largest, np.arange(len(parallel))]
    return plane


def _relative(area: np.ndarray, size: np.ndarray) -> np.ndarray:
    """area / size**2, and 0 where the size is 0."""
    scale = size**2
    return np.divide(area, scale, out=np.zeros_like(area), where=scale > 0)


def degeneracy(quads: PlanarQuads) -> np.ndarray:
    """Area of the smallest of the four split triangles, relative to the squared longest edge.

    The triangles opposite the corners are the two triangles of either diagonal
    split, so a repeated corner, a collapsed edge, three collinear corners or a
    zero-area quad all give 0, and so does a triangle whose area is within
    rounding of zero for its coordinates' magnitude (``PlanarQuads.rounding``:
    moving a mesh far from the origin must not turn a degenerate quad into a
    sliver). Rule Q201 flags values at or below its threshold; with the default
    threshold those are exactly the quads with a triangle the affinity test
    treats as vanished.

    Returns
    -------
    (Q,) float64 in [0, ~0.5].
    """
    smallest = np.abs(quads.areas).min(axis=1)
    smallest[smallest <= quads.rounding] = 0.0
    return _relative(smallest / 2, quads.size)


def relative_signed_area(quads: PlanarQuads) -> np.ndarray:
    """The quads' signed area (T_0 + T_2) / 2 relative to the squared longest edge.

    Meaningful for 2-D corners (texture coordinates: negative = clockwise, a
    mirrored UV, rule Q302; near zero = rule Q301). For 3-D corners it is never
    negative, since the plane's normal follows the diagonals.

    Returns
    -------
    (Q,) float64, 0 for a quad collapsed to a point.
    """
    return _relative((quads.areas[:, 0] + quads.areas[:, 2]) / 2, quads.size)


def zero_area(quads: PlanarQuads, threshold: float) -> np.ndarray:
    """Quads collapsed to a segment or a point: the whole area (T_0 + T_2) / 2 within rounding of zero
    or at most ``threshold`` times the squared longest edge.

    A quad with one repeated corner (a pole quad) is a triangle with area: not zero.

    Returns
    -------
    (Q,) bool
    """
    doubled = quads.areas[:, 0] + quads.areas[:, 2]
    return (np.abs(doubled) <= quads.rounding) | (np.abs(_relative(doubled / 2, quads.size)) <= threshold)


def _fold(C: np.ndarray, sides: np.ndarray, a: int, b: int) -> np.ndarray:
    """(Q,) float64 degrees between the normals C_a, C_b (3, Q) of two triangles of a split,
    each taken on the side of the quad's normal: ``sides`` (4, Q) holds sign(C_i . n).

    On the quad normal's side (n = d02 x d13) a flat concave or self-crossing quad, whose
    wrong split overlaps itself, folds nothing (that is Q203's and Q204's). A triangle
    without area has no normal and folds nothing either: that quad is Q201's.
    """
    side = sides[a] * sides[b]  # the angle between s_a C_a and s_b C_b, s = +-1 or 0
    sine = np.sqrt(squared_lengths(cross_by_component(C[:, a], C[:, b])))
    sine *= np.abs(side)
    cosine = dot_by_component(C[:, a], C[:, b])
    cosine *= side
    cosine += 0.0  # a zeroed normal gives -0: atan2(0, -0) would be 180
    return np.degrees(np.arctan2(sine, cosine))


def fold_degrees(quads: PlanarQuads, diagonal: str) -> np.ndarray:
    """(Q,) float64 fold angle in degrees of 3-D quads (PlanarQuads of Q quads).

    The angle between the normals of the two triangles of the split along 0-2
    (triangles 012 and 023, opposite corners 3 and 1) or 1-3 (123 and 130, opposite
    corners 0 and 2), as the dihedral angle of the split surface: 0 for a planar
    quad (see :func:`_fold`), atan2(|n1 x n2|, n1 . n2). ``diagonal`` is the
    setting: ``"02"``, ``"13"``, ``"both"`` (the worse of the two) or
    ``"shortest"`` (the diagonal shorter in 3-D).
    """
    C = quads.vector_areas
    sides = np.sign(dot_by_component(C, quads.normals[:, None]))
    if diagonal == "02":
        return _fold(C, sides, 3, 1)
    if diagonal == "13":
        return _fold(C, sides, 0, 2)
    fold02, fold13 = _fold(C, sides, 3, 1), _fold(C, sides, 0, 2)
    if diagonal == "shortest":
        return np.where(quads.diagonals[:, 0] <= quads.diagonals[:, 1], fold02, fold13)
    return np.maximum(fold02, fold13, out=fold02)


def is_bowtie(quads: PlanarQuads) -> np.ndarray:
    """Quads that cross themselves in their own plane.

    The plane's normal makes T_0 + T_2 = T_1 + T_3 >= 0, so at most one turn of
    each opposite pair is clockwise: one clockwise turn is a reflex corner
    (concave quad), two are the two sides of a crossing (bow-tie).

    Returns
    -------
    (Q,) bool
    """
    return quads.reflex.sum(axis=1, dtype=np.int8) == 2  # int8: a sum of 4 flags, without an int64 cast


def folded_fraction(quads: PlanarQuads) -> np.ndarray:
    """Share of the corner-turn area that turns clockwise: sum of |T_i| over clockwise
    turns / sum of |T_i|. In (0, 0.5] for a bow-tie (0.5 for a symmetric one),
    0 for a convex quad.

    Returns
    -------
    (Q,) float64
    """
    magnitude = np.abs(quads.areas)
    folded = np.where(quads.reflex, magnitude, 0).sum(axis=1)
    total = magnitude.sum(axis=1)
    return np.divide(folded, total, out=np.zeros_like(total), where=total > 0)


def interior_angles(quads: PlanarQuads) -> np.ndarray:
    """Interior angle at every corner in the quad's plane, in degrees.

    angle_k = 180 - atan2(turn_k, e_in . e_out) in degrees, with e_in = p_k - p_{k-1},
    e_out = p_{k+1} - p_k, both projected onto the quad's plane, and turn_k = e_in x e_out
    = T_{k+2} (the triangle (p_{k-1}, p_k, p_{k+1})); above 180 at a reflex corner. The
    projected dot product is e_in . e_out - (e_in . n)(e_out . n) for the unit plane normal
    n, so nothing is projected. Turns within the degenerate tolerance are taken as exactly
    0, so three collinear corners read 180, not a reflex 180 plus rounding. Meaningful for
    simple (non-bow-tie) quads.

    Returns
    -------
    (Q, 4) float64
    """
    e = _edges(quads.components)
    e_in, e_out = e[:, [3, 0, 1, 2]], e[:, :4]  # (D, 4, Q): into and out of corners 0..3
    dot = dot_by_component(e_in, e_out)
    if quads.plane_normals is not None:
        n = quads.plane_normals
        length = np.sqrt(squared_lengths(n))
        n = np.divide(n, length, out=np.zeros_like(n), where=length > 0)[:, None]
        dot -= dot_by_component(e_in, n) * dot_by_component(e_out, n)
    turn = quads.areas[:, _CORNER_TURN_AT].T
    turn[np.abs(turn) <= quads.tolerance] = 0.0
    return 180.0 - np.degrees(np.arctan2(turn, dot)).T
