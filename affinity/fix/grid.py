"""The n x n grid of a quad's own bilinear surface, the refinement ``affinity fix`` applies.

A quad with corners q0..q3 is the bilinear patch
P(s, t) = (1-s)(1-t) q0 + s(1-t) q1 + s t q2 + (1-s) t q3 (design.md, "The affinity test"),
and its attribute the same blend of the corner values. Refining it at level n puts a
vertex at every (s, t) = (i/n, j/n) (and the cuts beside it at the points of their
patterns, :mod:`affinity.fix.patterns`) and carries the blended values there, so each
piece is the patch's own: the refined mesh describes the same surface and the same
attribute field as the quad did, and its split, taken piece by piece, converges to it
(the split error of a piece falls about as 1/n^2).
"""

from __future__ import annotations

import numpy as np


def weights_at(st: np.ndarray) -> np.ndarray:
    """Weights of the four corners at the parameters ``st`` (P, 2) float64 (s, t).

    Returns
    -------
    (P, 4) float64: ((1-s)(1-t), s(1-t), s t, (1-s) t), summing to 1.
    """
    s, t = np.asarray(st, dtype=np.float64).T
    return np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t], axis=1)
