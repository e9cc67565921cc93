"""The properties every method is checked for, measured scale-free and exactly.

- ``error``: distance to the exact result (``reference``), infinity norm per
  point, absolute, or relative to the exact result's largest component.
- ``unity``: partition of unity, |sum_i lambda_i - 1| / max(1, sum_i |lambda_i|).
- ``linear``: linear precision, |sum_i W_i s_i| / scale with the exact
  offsets s_i = q_i - p, evaluated exactly (mpmath). For mean value
  coordinates W_i = lambda_i w_i (the homogeneous form of eq. 10, so it holds
  behind the eye too) and scale = sum_i |W_i| |s_i|: a backward error, since
  weights exact for offsets moved by a relative e have ``linear`` <= e. For
  (s, t), W_i are the bilinear weights, the sum is the residual P(s, t) - p of
  the inverse map, and scale = extent * max(1, |s|) * max(1, |t|): (s, t) are
  absolute quantities (near 1, 1 - s has lost its relative precision), and
  rounding the exact (s, t) moves P by about u times that.
- ``leak``: the Lagrange property, the weight a method puts on other corners
  when evaluated at a corner (corners equal to it, e.g. a pole's repeated
  corner, share its weight).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np

from .reference import DIGITS


def error(result, hi, lo, relative) -> np.ndarray:
    """Per-point error (N,) of ``result`` (N, K) against the exact hi + lo (N, K)
    (a float64 pair); NaN where the result is not finite."""
    result = np.asarray(result, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        e = np.abs((result - hi) - lo).max(axis=1)
        if relative:
            e = e / np.abs(hi).max(axis=1)
    return np.where(np.isfinite(result).all(axis=1), e, np.nan)


def unity(lam) -> np.ndarray:
    """Partition-of-unity defect (N,) of weights (N, 4), summed exactly."""
    lam = np.asarray(lam, dtype=np.float64)
    total = np.array([math.fsum([*row, -1.0]) if np.isfinite(row).all() else np.nan for row in lam])
    return np.abs(total) / np.maximum(1.0, np.abs(lam).sum(axis=1))


def mean_value_linear(lam, w, offsets) -> np.ndarray:
    """Linear-precision defect (N,) of weights ``lam`` (N, 4) with w (4,) or None;
    ``offsets``: per point the exact s_i (``reference.offsets``)."""
    lam = np.asarray(lam, dtype=np.float64)
    w = np.ones(4) if w is None else np.asarray(w, dtype=np.float64)
    with mpmath.workdps(DIGITS):
        weights = [[mpmath.mpf(float(v)) * mpmath.mpf(float(x)) for v, x in zip(row, w)] for row in lam]
    return _defect(weights, offsets, None)


def bilinear_linear(st, offsets, quad) -> np.ndarray:
    """Residual of the inverse map (N,) for parameters ``st`` (N, 2) in ``quad``
    (4, 2), relative to extent * max(1, |s|) * max(1, |t|)."""
    st = np.asarray(st, dtype=np.float64)
    quad = np.asarray(quad, dtype=np.float64)
    extent = float(np.abs(quad[:, None] - quad[None]).max())
    scale = extent * np.maximum(1.0, np.abs(st[:, 0])) * np.maximum(1.0, np.abs(st[:, 1]))
    with mpmath.workdps(DIGITS):
        weights = []
        for s, t in st:
            s, t = mpmath.mpf(float(s)), mpmath.mpf(float(t))
            weights.append([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t])
    return _defect(weights, offsets, scale)


def _defect(weights, offsets, scale):
    """max_k |sum_i W_i s_i[k]| / scale per point (scale None: sum_i |W_i s_i[k]|, max over k)."""
    out = np.empty(len(weights))
    with mpmath.workdps(DIGITS):
        for n, (W, s) in enumerate(zip(weights, offsets)):
            if not all(mpmath.isfinite(v) for v in W):
                out[n] = np.nan
                continue
            terms = [[W[i] * s[i][k] for i in range(4)] for k in range(2)]
            residual = max(abs(mpmath.fsum(row)) for row in terms)
            size = max(mpmath.fsum(abs(v) for v in row) for row in terms) if scale is None else scale[n]
            out[n] = float(residual / size) if size else 0.0
    return out


def leak(weights, quad) -> float:
    """Largest weight on other corners, with ``weights`` (4, 4) evaluated at the
    corners of ``quad`` (4, 2) (row j at corner j); NaN if not finite."""
    weights = np.asarray(weights, dtype=np.float64)
    if not np.isfinite(weights).all():
        return float("nan")
    other = ~(quad[:, None, :] == quad[None, :, :]).all(axis=2)  # corner k is not corner j
    return float(np.where(other, np.abs(weights), 0.0).sum(axis=1).max())
