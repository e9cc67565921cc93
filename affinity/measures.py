"""The affinity test of Bloomenthal 2022 (JCGT 11(3), Listing 3), vectorized and made robust.

Is a quad's attribute (texture coordinates, colours, normals) an affine image of
its positions? Listing 3 takes each corner i and its barycentric coordinates
b_ij with respect to the other three corners j = i+1, i+2, i+3 (mod 4), once in
position space and once in attribute space, and calls the quad affine when the
two agree. The defects of the listing are fixed here (design.md, "The affinity
test"): triangle areas are signed in the quad's own plane
(measured along the quad's own normal, ``affinity.geometry.PlanarQuads``), not by ``v.z``; degenerate reference
triangles are marked invalid by a tolerance relative to the quad's size
(``affinity.geometry.DEGENERATE_AREA``), never an absolute ``FLT_EPSILON``, and
skipped explicitly; attributes may have any dimension.

Closed form used throughout. With T_i the doubled signed area of the triangle
opposite corner i (``affinity.geometry.PlanarQuads.areas``), the four corners obey
the affine dependency sum_k (-1)^k T_k p_k = 0 with sum_k (-1)^k T_k = 0, hence

    b_ij = (-1)^(i+j+1) T_j / T_i      (j != i),

i.e. b_i = (T_{i+1}, -T_{i+2}, T_{i+3}) / T_i, and the residual of corner i is

    a_i - sum_j b_ij a_j = (-1)^i R / T_i,   R = sum_k (-1)^k T_k a_k.

All four residuals are one vector R divided by the corner's own area, so the
largest belongs to the valid selected corner with the smallest |T_i|.

Three readings are reported (design.md, "The affinity test"):

* ``error`` (the default): the largest difference over the quad between the
  two-triangle split and the bilinear interpolation of the corner values in the
  quad's own parameters (s, t), the surface the quad describes;
* ``centre``: the split's shift at the corner mean;
* ``barycentric``: max_i |b_i(positions) - b_i(uv)|, the paper's dimensionless
  score (tolerance .01), invariant to translation, rotation and scale of either
  space.

Derivation of ``error`` (split along 0-2; 1-3 is the same with the corners
turned by one). Let P(s, t) = (1-s)(1-t) p0 + s(1-t) p1 + s t p2 + (1-s) t p3 be
the bilinear position map and A(s, t) the same blend of the attribute values.
The split draws triangle (0, 1, 2), of doubled area T_3, with the affine function
L that takes the values a_0, a_1, a_2 at its corners. L o P is bilinear in (s, t)
(an affine function of a bilinear map), equal to A at corners 0, 1, 2 and to
L(p_3) at corner 3, so

    L(P(s, t)) - A(s, t) = (1-s) t (L(p_3) - a_3) = (1-s) t R / T_3,

since a_3 - L(p_3) is corner 3's residual -R / T_3. Likewise triangle (0, 2, 3),
of doubled area T_1, gives s (1-t) R / T_1 (corner 1's residual is -R / T_1). The
error is a multiple of the one vector R everywhere. The two triangles meet on the diagonal,
whose preimage in (s, t) is where the signed area of (p_0, p_2, P(s, t)), the
bilinear s (1-t) (-T_3) + (1-s) t T_1 (over 2), vanishes: the boundary curve

    T_1 (1-s) t = T_3 s (1-t),

from (0, 0) to (1, 1). On the side of corner 1 the error is (1-s) t R / T_3,
which is the smaller of the two expressions there (and vice versa), so over a
convex quad |E(s, t)| = |R| min((1-s) t / T_3, s (1-t) / T_1), whose maximum lies
on the boundary curve. Along it t = T_3 s / (T_1 (1-s) + T_3 s); maximising
(1-s) t gives

    (s*, t*) = (sqrt T_1, sqrt T_3) / (sqrt T_1 + sqrt T_3)   (so t* = 1 - s*),

    max |E| = |R| (1-s*) t* / T_3 = |R| / (sqrt T_1 + sqrt T_3)^2.

On a parallelogram (T_1 = T_3 = T) that is |R| / (4 T), the shift at the centre;
on an exact pole quad (p_0 = p_1: T_3 = 0, T_0 = T_1, R = T_1 (a_0 - a_1)) it is
|a_0 - a_1|, the whole width of the quad's attribute. Nothing divides by a small
area: the denominator is at least the larger of T_1, T_3, and a quad is skipped
only when both vanish (Q201). For a convex quad the split's and the bilinear
values are both convex combinations of the corner values, so |E| never exceeds
the largest distance between two corners.

Where the diagonal runs outside the quad (T_3 < 0: reflex corner 1) the quad is
triangle (0, 2, 3) minus triangle (0, 1, 2), so the split shows L_(0,2,3) on all
of it and |E| = |R| s (1-t) / T_1 <= |R| / T_1, the value at corner 1's
parameters (1, 0): the same closed form with T_3 taken as 0, so negative areas
enter as 0. Where the diagonal runs inside a concave quad (reflex corner 0 or 2)
or the quad is a bow-tie, the bilinear map folds and (s*, t*) may map outside the
quad. In these nonconvex cases the closed form is an upper bound of the largest
error over the parameters whose image lies inside the quad (not that maximum
itself: near a reflex corner the bilinear map folds outward), and it is capped at
the attribute's corner extent (the largest distance between two corner values),
which the split's values inside the quad cannot leave (Q203/Q204 report the shape).

Which corners count is the ``diagonal`` setting: corners 1 and 3 measure the
split along 0-2 (areas T_1, T_3 are its triangles), corners 0 and 2 the split
along 1-3; ``"both"`` takes the worse diagonal (the larger scale, R being the
same vector for both), ``"shortest"`` the diagonal shorter in 3-D.
"""

from __future__ import annotations

import numpy as np

from .geometry import PlanarQuads, lengths, squared_lengths

_CORNERS_OF_DIAGONAL = {
    "both": np.array([True, True, True, True]),
    "02": np.array([False, True, False, True]),
    "13": np.array([True, False, True, False]),
}


def selected_corners(quads: PlanarQuads, diagonal: str = "both") -> np.ndarray:
    """Corners whose test measures the chosen split.

    Parameters
    ----------
    quads : PlanarQuads of Q quads (positions; ``diagonals`` picks ``"shortest"``).
    diagonal : {"both", "02", "13", "shortest"}
        ``"shortest"`` takes 0-2 where it is at most as long as 1-3 in 3-D.

    Returns
    -------
    (Q, 4) bool
    """
    if diagonal == "shortest":
        along_02 = quads.diagonals[:, 0] <= quads.diagonals[:, 1]
        return np.where(along_02[:, None], _CORNERS_OF_DIAGONAL["02"], _CORNERS_OF_DIAGONAL["13"])
    if diagonal not in _CORNERS_OF_DIAGONAL:
        raise ValueError(f"diagonal must be one of both, 02, 13, shortest; got {diagonal!r}")
    return np.broadcast_to(_CORNERS_OF_DIAGONAL[diagonal], (len(quads), 4))


def corner_barycentrics(quads: PlanarQuads) -> np.ndarray:
    """Barycentric coordinates of every corner with respect to the other three.

    b[q, i] = (b_i,i+1, b_i,i+2, b_i,i+3) = (T_{i+1}, -T_{i+2}, T_{i+3}) / T_i, so that
    p_i = sum_j b_ij p_j and sum_j b_ij = 1 (Bloomenthal 2022, Listing 3, ``Bary``).

    Parameters
    ----------
    quads : PlanarQuads of Q quads (positions or texture coordinates).

    Returns
    -------
    (Q, 4, 3) float64, NaN where the reference triangle is degenerate
    (``~quads.valid``).
    """
    T = quads.areas
    numerators = np.stack(
        [np.roll(T, -1, axis=1), -np.roll(T, -2, axis=1), np.roll(T, -3, axis=1)], axis=-1
    )
    valid = quads.valid[..., None]
    return np.divide(numerators, T[..., None], out=np.full(numerators.shape, np.nan), where=valid)


#: The two triangles of each diagonal's split, by the corner each is opposite to:
#: along 0-2 the triangles (0, 2, 3) and (0, 1, 2), of doubled areas T_1 and T_3.
_TRIANGLES_OF_DIAGONAL = {"02": (1, 3), "13": (0, 2)}


def split_error(quads: PlanarQuads, attrs: np.ndarray, diagonal: str = "both", measure: str = "error") -> np.ndarray:
    """The split's error vector E of an attribute, in the attribute's units.

    ``measure="error"``: the largest split-minus-bilinear difference over the quad,
    R / (sqrt T_a + sqrt T_b)^2 (module docstring); ``"centre"``: the difference at
    the corner mean, R / (4 max(|T_a|, |T_b|)). T_a, T_b are the doubled areas of
    the diagonal's two triangles, R = sum_k (-1)^k T_k a_k. With ``diagonal="both"``
    the worse diagonal counts. A quad whose diagonal's two triangles both vanish
    (Q201) scores 0.

    Parameters
    ----------
    quads : PlanarQuads of Q quads (positions, from ``planar_quads``).
    attrs : (Q, 4, K) float64
        Attribute values at the corners, any dimension K.
    diagonal : {"both", "02", "13", "shortest"}
    measure : {"error", "centre"}

    Returns
    -------
    (Q, K) float64 split minus bilinear at the worst point (at the corner mean
    for ``"centre"``), always finite; its direction is +-R's.
    """
    return split_error_by_component(quads, np.transpose(attrs, (2, 1, 0)), diagonal, measure).T


def residual_by_component(areas: np.ndarray, attrs: np.ndarray) -> np.ndarray:
    """R = sum_k (-1)^k T_k a_k, taken relative to corner 0 (exact, since
    sum_k (-1)^k T_k = 0) so attributes far from zero keep their digits.

    areas : (4, Q) float64, T_i of every quad at [i]; attrs : (K, 4, Q) float64.
    Returns (K, Q) float64.
    """
    a0 = attrs[:, 0]
    R = attrs[:, 2] - a0
    R *= areas[2]
    R -= (attrs[:, 1] - a0) * areas[1]
    R -= (attrs[:, 3] - a0) * areas[3]
    return R


def split_error_by_component(quads: PlanarQuads, attrs: np.ndarray, diagonal: str = "both", measure: str = "error",
                             scale: np.ndarray | None = None) -> np.ndarray:
    """:func:`split_error` of attributes laid out by component.

    Parameters
    ----------
    quads : PlanarQuads of Q quads.
    attrs : (K, 4, Q) float64, component k of corner i of quad q at [k, i, q].
    diagonal : {"both", "02", "13", "shortest"}
    measure : {"error", "centre"}
    scale : (Q,) float64, ``split_scale(quads, diagonal, measure)`` when already
        known (it depends on the positions only, so several attributes share it).

    Returns
    -------
    (K, Q) float64
    """
    E = residual_by_component(quads.areas.T, attrs)
    E *= split_scale(quads, diagonal, measure) if scale is None else scale
    if measure == "error":
        folded, factor = _extent_caps(quads, attrs, E)
        E[:, folded] *= factor
    return E


def _extent_caps(quads: PlanarQuads, attrs: np.ndarray, E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The quads with a reflex corner (concave, bow-tie), where the closed form is only an upper
    bound, (n,) int64, and the factors (n,) float64 in (0, 1] that scale their E (K, Q) down to the
    attribute's corner extent (the largest distance between two corner values)."""
    folded = np.flatnonzero(quads.reflex.any(axis=1))
    if len(folded) == 0:
        return folded, np.ones(0)
    a = attrs[:, :, folded]
    extent = np.zeros(len(folded))
    for i, j in ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)):
        np.maximum(extent, np.sqrt(squared_lengths(a[:, i] - a[:, j])), out=extent)
    length = np.sqrt(squared_lengths(E[:, folded]))
    return folded, np.divide(extent, length, out=np.ones_like(length), where=length > extent)


def _diagonal_scale(quads: PlanarQuads, diagonal: str, measure: str) -> np.ndarray:
    """(Q,) scale of one diagonal ("02" or "13"); see :func:`split_scale`."""
    a, b = _TRIANGLES_OF_DIAGONAL[diagonal]
    T_a, T_b = quads.areas[:, a], quads.areas[:, b]
    if measure == "centre":
        denominator = 4 * np.maximum(np.abs(T_a), np.abs(T_b))
    elif measure == "error":
        # A negative area is the triangle outside the quad: it enters as 0 (module docstring).
        denominator = np.sqrt(np.maximum(T_a, 0)) + np.sqrt(np.maximum(T_b, 0))
        denominator *= denominator
    else:
        raise ValueError(f"measure must be error or centre; got {measure!r}")
    vanish = np.maximum(np.abs(T_a), np.abs(T_b)) <= quads.tolerance
    # Split minus bilinear is +R c along 0-2 (corners 1, 3 have residuals -R / T_i) and
    # -R c along 1-3 (corners 0, 2 have +R / T_i).
    sign = 1.0 if diagonal == "02" else -1.0
    return np.divide(sign, denominator, out=np.zeros_like(denominator), where=~vanish & (denominator > 0))


def split_scale(quads: PlanarQuads, diagonal: str = "both", measure: str = "error") -> np.ndarray:
    """c with E = c R (split minus bilinear): +-1 / (sqrt T_a + sqrt T_b)^2 for
    ``"error"``, +-1 / (4 max(|T_a|, |T_b|)) for ``"centre"``, over the diagonal's
    two triangles, + along 0-2 and - along 1-3; the larger in magnitude of the two
    diagonals' for ``"both"``; 0 where the diagonal's two triangles both vanish.

    Returns
    -------
    (Q,) float64
    """
    if diagonal in _TRIANGLES_OF_DIAGONAL:
        return _diagonal_scale(quads, diagonal, measure)
    if diagonal not in ("both", "shortest"):
        raise ValueError(f"diagonal must be one of both, 02, 13, shortest; got {diagonal!r}")
    along_02, along_13 = _diagonal_scale(quads, "02", measure), _diagonal_scale(quads, "13", measure)
    if diagonal == "both":
        return np.where(np.abs(along_13) > np.abs(along_02), along_13, along_02)
    return np.where(quads.diagonals[:, 0] <= quads.diagonals[:, 1], along_02, along_13)


def split_error_point(T_a: np.ndarray, T_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Parameters (s*, t*) of the largest split error along diagonal 0-2:
    (sqrt T_1, sqrt T_3) / (sqrt T_1 + sqrt T_3), negative areas taken as 0.

    T_a, T_b : (Q,) float64, T_1 and T_3. Returns two (Q,) float64; (0.5, 0.5)
    where both vanish.
    """
    root_a, root_b = np.sqrt(np.maximum(T_a, 0)), np.sqrt(np.maximum(T_b, 0))
    total = root_a + root_b
    s = np.divide(root_a, total, out=np.full_like(total, 0.5), where=total > 0)
    return s, 1 - s


def barycentric_score(quads: PlanarQuads, uv_quads: PlanarQuads, diagonal: str = "both") -> np.ndarray:
    """The paper's own score: max_i |b_i(positions) - b_i(uv)| (L2 norm), tolerance .01.

    Dimensionless and invariant to translation, rotation and scale of either
    space. Corners whose reference triangle is degenerate in either space are
    skipped (Listing 3 would fail silently there); a quad with no usable corner
    scores 0.

    Parameters
    ----------
    quads : PlanarQuads of Q quads (positions).
    uv_quads : PlanarQuads of the same Q quads' texture coordinates (2-D).
    diagonal : {"both", "02", "13", "shortest"}

    Returns
    -------
    (Q,) float64
    """
    distance = lengths(corner_barycentrics(quads) - corner_barycentrics(uv_quads))
    usable = quads.valid & uv_quads.valid & selected_corners(quads, diagonal)
    return np.where(usable, distance, 0.0).max(axis=1)


def texels(m: np.ndarray, texture_size) -> np.ndarray:
    """A split error of texture coordinates in texels: |(m_u W, m_v H)|.

    Parameters
    ----------
    m : (Q, 2) float64 split error in uv units.
    texture_size : int, (width, height), or (Q, 2) float per quad

    Returns
    -------
    (Q,) float64
    """
    size = np.asarray(texture_size, dtype=np.float64)
    return lengths(m * (size if size.ndim else np.broadcast_to(size, (2,))))


def color_steps(m: np.ndarray) -> np.ndarray:
    """A split error of colours in [0, 1] in 1/255 steps: |m| * 255.

    Parameters
    ----------
    m : (Q, K) float64

    Returns
    -------
    (Q,) float64
    """
    return lengths(m) * 255.0


def normal_degrees(m: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """A split error of normals as the angle it turns the mean corner normal, in degrees.

    angle = atan2(|m|, |mean_k n_k|), the largest turn of the centre normal by a
    displacement m (atan2 stays accurate for small angles, unlike acos).

    Parameters
    ----------
    m : (Q, 3) float64 split error measured on ``normals``.
    normals : (Q, 4, 3) float64 the corner normals m was measured on (unit length).

    Returns
    -------
    (Q,) float64 in [0, 90].
    """
    mean_normal = lengths(normals[:, 0] + normals[:, 1] + normals[:, 2] + normals[:, 3]) / 4
    return np.degrees(np.arctan2(lengths(m), mean_normal))

