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

Two readings are reported (design.md):

* ``misplacement``: m = (a_i - sum_j b_ij a_j) / 4 for the corner i of largest
  norm: how far the two-triangle split moves the attribute at the quad's centre.
  For a parallelogram (all T_i equal) it is exactly the bilinear value at the
  centre minus the split's value there, +-(a_0 - a_1 + a_2 - a_3) / 4. For other
  planar quads the centre (the corner mean) lies in the larger triangle of the
  split, so the exact shift is the residual of the diagonal's corner with the
  larger |T_i|; the largest residual taken here (design.md) exceeds it by the
  ratio of the two triangles' areas, e.g. (1 - r) / (4r) against (1 - r) / 4 on
  a trapezoid with a unit-square uv whose parallel sides have the ratio r.
* ``barycentric``: max_i |b_i(positions) - b_i(uv)|, the paper's dimensionless
  score (tolerance .01), invariant to translation, rotation and scale of either
  space.

Which corners count is the ``diagonal`` setting: corners 1 and 3 measure the
split along 0-2, corners 0 and 2 the split along 1-3; ``"both"`` takes all four,
``"shortest"`` the diagonal shorter in 3-D.
"""

from __future__ import annotations

import numpy as np

from .geometry import PlanarQuads, lengths

_ALTERNATING = np.array([1.0, -1.0, 1.0, -1.0])

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


def misplacement(quads: PlanarQuads, attrs: np.ndarray, diagonal: str = "both") -> np.ndarray:
    """How far the two-triangle split moves an attribute at the quad's centre.

    m = (a_i - sum_j b_ij a_j) / 4 = (-1)^i R / (4 T_i),  R = sum_k (-1)^k T_k a_k,

    for the corner i of largest |m| among the corners selected by ``diagonal``
    whose reference triangle is not degenerate. Corners with a degenerate
    reference triangle are skipped, so a pole quad (two corners at the pole) is
    scored by its two other corners; a quad with no usable corner (collapsed to a
    line or a point, reported by Q201) scores 0.

    Parameters
    ----------
    quads : PlanarQuads of Q quads (positions, from ``planar_quads``).
    attrs : (Q, 4, K) float64
        Attribute values at the corners, any dimension K.
    diagonal : {"both", "02", "13", "shortest"}

    Returns
    -------
    (Q, K) float64 vector m in the attribute's units; always finite.
    """
    return misplacement_by_component(quads, np.transpose(attrs, (2, 1, 0)), diagonal).T


def misplacement_by_component(quads: PlanarQuads, attrs: np.ndarray, diagonal: str = "both", scale: np.ndarray | None = None) -> np.ndarray:
    """:func:`misplacement` of attributes laid out by component.

    Parameters
    ----------
    quads : PlanarQuads of Q quads.
    attrs : (K, 4, Q) float64, component k of corner i of quad q at [k, i, q].
    diagonal : {"both", "02", "13", "shortest"}
    scale : (Q,) float64, ``split_scale(quads, diagonal)`` when already known
        (it depends on the positions only, so several attributes share it).

    Returns
    -------
    (K, Q) float64
    """
    T = quads.areas.T  # (4, Q): T[i] holds every quad's T_i
    # Relative to corner 0 (sum_k (-1)^k T_k = 0 makes this exact), so attributes far
    # from zero keep their digits.
    a0 = attrs[:, 0]
    R = attrs[:, 2] - a0
    R *= T[2]
    R -= (attrs[:, 1] - a0) * T[1]
    R -= (attrs[:, 3] - a0) * T[3]
    R *= split_scale(quads, diagonal) if scale is None else scale
    return R


def split_scale(quads: PlanarQuads, diagonal: str = "both") -> np.ndarray:
    """1 / (4 (-1)^i T_i) for the corner i that :func:`misplacement` reads: among
    the corners selected by ``diagonal`` whose reference triangle is not
    degenerate, the one with the smallest |T_i| (the first of equals); 0 where
    no corner is usable.

    Returns
    -------
    (Q,) float64
    """
    T = quads.areas.T
    usable = quads.valid.T & selected_corners(quads, diagonal).T
    smallest = np.full(len(quads), np.inf)
    signed_area = np.zeros(len(quads))  # (-1)^i T_i of the chosen corner i
    for i in range(4):  # the four corners, each vectorized over all quads
        candidate = np.where(usable[i], np.abs(T[i]), np.inf)
        smaller = candidate < smallest
        smallest = np.where(smaller, candidate, smallest)
        signed_area = np.where(smaller, _ALTERNATING[i] * T[i], signed_area)
    return np.divide(0.25, signed_area, out=np.zeros_like(signed_area), where=signed_area != 0)


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
    """Misplacement of texture coordinates in texels: |(m_u W, m_v H)|.

    Parameters
    ----------
    m : (Q, 2) float64 misplacement in uv units.
    texture_size : int or (width, height)

    Returns
    -------
    (Q,) float64
    """
    return lengths(m * np.broadcast_to(np.asarray(texture_size, dtype=np.float64), (2,)))


def color_steps(m: np.ndarray) -> np.ndarray:
    """Misplacement of colours in [0, 1] in 1/255 steps: |m| * 255.

    Parameters
    ----------
    m : (Q, K) float64

    Returns
    -------
    (Q,) float64
    """
    return lengths(m) * 255.0


def normal_degrees(m: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Misplacement of normals as the angle it turns the mean corner normal, in degrees.

    angle = atan2(|m|, |mean_k n_k|), the largest turn of the centre normal by a
    displacement m (atan2 stays accurate for small angles, unlike acos).

    Parameters
    ----------
    m : (Q, 3) float64 misplacement measured on ``normals``.
    normals : (Q, 4, 3) float64 the corner normals m was measured on (unit length).

    Returns
    -------
    (Q,) float64 in [0, 90].
    """
    mean_normal = lengths(normals[:, 0] + normals[:, 1] + normals[:, 2] + normals[:, 3]) / 4
    return np.degrees(np.arctan2(lengths(m), mean_normal))


def pixel_error(values: np.ndarray, reference: np.ndarray, attribute: str, texture_size) -> np.ndarray:
    """Error of interpolated attributes against a reference's, in the lint's units.

    Parameters
    ----------
    values, reference : (N, K) float64, the attribute at N pixels
    attribute : the Mesh field they come from: ``"texcoords"``, ``"colors"`` or ``"normals"``
    texture_size : (width, height) in texels, for texture coordinates

    Returns
    -------
    (N,) float64: |du, dv| in texels, |d rgb| in 1/255 steps, or the angle
    between the two normals in degrees.
    """
    if attribute == "texcoords":
        return texels(values - reference, texture_size)
    if attribute == "colors":
        return color_steps(values - reference)
    cross = np.linalg.norm(np.cross(values, reference), axis=-1)
    return np.degrees(np.arctan2(cross, np.einsum("nk,nk->n", values, reference)))
