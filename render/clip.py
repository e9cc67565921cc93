"""Clipping of clip-space triangles against planes (Sutherland-Hodgman, vectorised).

A plane is a coefficient vector n (4,); a clip-space point P = (x, y, z, w) is
inside when n . P >= 0 (the near plane is n = (0, 0, 1, 1): z >= -w). Clipping
in homogeneous coordinates, before any division by w, is what lets triangles
with corners behind the eye (w < 0) or on the eye plane (w = 0) be drawn: only
their visible part survives, and it has w > 0.

New corners are interpolated from the inside corner towards the outside one,
so two triangles sharing an edge compute bit-identical corners on it and stay
watertight after clipping. Interpolating in clip space is exact for the
rasterizer, which takes attributes and depth from the original triangle.
"""

from __future__ import annotations

import numpy as np

ROTATIONS = np.array([[0, 1, 2], [1, 2, 0], [2, 0, 1]])


def plane_distances(tri, planes) -> np.ndarray:
    """n . P for every plane and corner: tri (4, 3, T), planes (k, 4) -> (k, 3, T).

    Evaluated term by term over the nonzero coefficients (not through a matrix
    product, whose rounding may depend on a row's position), so that a corner
    shared by several triangles gets bit-identical distances in all of them.
    """
    planes = np.asarray(planes, dtype=np.float64)
    out = np.zeros((planes.shape[0],) + tri.shape[1:])
    for d, plane in zip(out, planes):
        for i in np.flatnonzero(plane):
            d += plane[i] * tri[i]
    return out


def clip_triangles(tri, planes):
    """Clip triangles against planes, keeping the inside part of each.

    Parameters
    ----------
    tri : (4, 3, T) float64
        Clip-space corners, component-major: ``tri[:, k, t]`` is (x, y, z, w)
        of corner k of triangle t.
    planes : (k, 4) float
        Inside is n . P >= 0 for every plane.

    Returns
    -------
    clipped : (4, 3, T') float64
        Triangles wholly inside every plane. A triangle cut by a plane becomes
        one or two triangles with the same orientation (corner order); one
        wholly outside a plane disappears.
    parent : (T',) int64
        Index into ``tri`` of the triangle each one came from (unclipped
        triangles first, in input order).
    """
    outside = plane_distances(tri, planes) < 0  # (k, 3, T)
    a, b, c = outside[:, 0], outside[:, 1], outside[:, 2]
    hidden = (a & b & c).any(axis=0)
    cut = (a | b | c).any(axis=0) & ~hidden
    whole = np.flatnonzero(~hidden & ~cut)
    parent = np.flatnonzero(cut)
    pieces = np.take(tri, parent, axis=2).transpose(2, 1, 0)  # (R, 3, 4): few
    for plane in np.asarray(planes, dtype=np.float64):
        pieces, parent = _clip_against_plane(pieces, parent, plane)
    return np.concatenate([np.take(tri, whole, axis=2), pieces.transpose(2, 1, 0)], axis=2), np.concatenate(
        [whole, parent]
    )


def _clip_against_plane(tri, parent, plane):
    """One Sutherland-Hodgman pass: (T, 3, 4), (T,) -> (T', 3, 4), (T',)."""
    d = plane_distances(tri.transpose(2, 1, 0), plane[None])[0].T  # (T, 3)
    inside = d >= 0
    count = inside.sum(axis=1)

    # One corner inside: rotate it to the front, keep (a, ab, ac).
    rows = np.flatnonzero(count == 1)
    order = ROTATIONS[np.argmax(inside[rows], axis=1)]
    P, dd = tri[rows[:, None], order], d[rows[:, None], order]
    one = np.stack(
        [
            P[:, 0],
            _crossing(P[:, 0], P[:, 1], dd[:, 0], dd[:, 1]),
            _crossing(P[:, 0], P[:, 2], dd[:, 0], dd[:, 2]),
        ],
        axis=1,
    )
    one_parent = parent[rows]

    # Two corners inside: rotate the outside one to the back, keep the quad
    # (a, b, bc, ac) as the fan (a, b, bc), (a, bc, ac).
    rows = np.flatnonzero(count == 2)
    order = ROTATIONS[(np.argmin(inside[rows], axis=1) + 1) % 3]
    P, dd = tri[rows[:, None], order], d[rows[:, None], order]
    bc = _crossing(P[:, 1], P[:, 2], dd[:, 1], dd[:, 2])
    ac = _crossing(P[:, 0], P[:, 2], dd[:, 0], dd[:, 2])
    two = np.concatenate([np.stack([P[:, 0], P[:, 1], bc], axis=1), np.stack([P[:, 0], bc, ac], axis=1)])
    two_parent = np.concatenate([parent[rows], parent[rows]])

    whole = count == 3
    return (
        np.concatenate([tri[whole], one, two]),
        np.concatenate([parent[whole], one_parent, two_parent]),
    )


def _crossing(inner, outer, d_inner, d_outer) -> np.ndarray:
    """Point where the segment from an inside corner to an outside one meets the plane.

    inner, outer : (T, 4); d_inner >= 0 > d_outer : (T,). Returns (T, 4).
    """
    t = d_inner / (d_inner - d_outer)
    return inner + t[:, None] * (outer - inner)
