"""The n x n grid of a quad's own bilinear surface, the refinement ``affinity fix`` applies.

A quad with corners q0..q3 is the bilinear patch
P(s, t) = (1-s)(1-t) q0 + s(1-t) q1 + s t q2 + (1-s) t q3 (design.md, "The affinity test"),
and its attribute the same blend of the corner values. Refining it at level n puts a
vertex at every (s, t) = (i/n, j/n) and carries the blended values there, so each of the
n^2 sub-quads is the patch's own piece: the refined mesh describes the same surface and the
same attribute field as the quad did, and its split, taken piece by piece, converges to it
(the split error of a piece falls about as 1/n^2).
"""

from __future__ import annotations

from functools import cache

import numpy as np


@cache
def grid_parameters(n: int) -> np.ndarray:
    """(s, t) of the grid points of level ``n``, row by row (t outer, s inner).

    Returns
    -------
    (n + 1, n + 1, 2) float64: point (i, j) (s = i/n, t = j/n) at [j, i].
    """
    steps = np.arange(n + 1) / n
    s, t = np.meshgrid(steps, steps)
    return np.stack([s, t], axis=-1)


def weights_at(st: np.ndarray) -> np.ndarray:
    """Weights of the four corners at the parameters ``st`` (P, 2) float64 (s, t).

    Returns
    -------
    (P, 4) float64: ((1-s)(1-t), s(1-t), s t, (1-s) t), summing to 1.
    """
    s, t = np.asarray(st, dtype=np.float64).T
    return np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t], axis=1)


@cache
def bilinear_weights(n: int) -> np.ndarray:
    """Weights of the four corners at every grid point of level ``n``: (P, 4) float64, P = (n + 1)^2 in
    :func:`grid_parameters` order (:func:`weights_at`)."""
    return weights_at(grid_parameters(n).reshape(-1, 2))


@cache
def sub_quads(n: int) -> np.ndarray:
    """The n^2 sub-quads of level ``n`` as grid point indices, oriented as the quad.

    Returns
    -------
    (n^2, 4) int64: sub-quad (i, j) at row j n + i has corners (i, j), (i+1, j),
    (i+1, j+1), (i, j+1) (grid point (i, j) is index j (n + 1) + i), so its corner k
    sits where the quad's corner k does.
    """
    j, i = np.divmod(np.arange(n * n), n)
    first = j * (n + 1) + i
    return np.stack([first, first + 1, first + n + 2, first + n + 1], axis=1)


def blend(corner_values: np.ndarray, n: int) -> np.ndarray:
    """The bilinear blend of corner values at the grid points of level ``n``.

    Parameters
    ----------
    corner_values : (Q, 4, K) float64

    Returns
    -------
    (Q, P, K) float64, P = (n + 1)^2; NaN where a corner value is NaN.
    """
    return np.einsum("pk,qkd->qpd", bilinear_weights(n), corner_values)
