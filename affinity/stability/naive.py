"""The naive forms issue 11 replaces, kept to show where they break.

Used only by the stability table and its tests, never by the product. Each has
the signature of its ``render.coords`` counterpart for one quad: ``p`` (N, 2),
``quad`` (4, 2), ``w`` (4,) or None, computed in the inputs' float dtype
(float32 stays float32), with no guard against NaN or inf.

Mean value coordinates (Hormann & Tarini 2004, eq. 7, 8, 10, 11):

- ``mean_value_acos``: alpha_i = sign(A_i) acos(D_i / (|s_i| |s_{i+1}|)),
  then tan(alpha_i / 2). acos loses half the digits near 0 and pi, and
  sign(0) = 0 puts a point on an edge at alpha = 0.
- ``mean_value_guarded``: Bloomenthal 2022, Listing 2 (HT04's pseudocode),
  t_i = (r_i r_{i+1} - D_i) / A_i with the absolute guard
  ``abs(A) < 1e-6 ? 0``: 0 where the limit is infinite (on an edge), every t
  0 and the weights 0 / 0 for a quad of size 1e-4, and the first form
  cancels for small angles.
- ``mean_value_cross_area``: the project's tangents (``render.coords``) with
  the paper's A_i = s_i x s_{i+1} (and the diagonal terms from the offsets,
  not the corners): two long, nearly parallel vectors for a point far from a
  short edge, which loses (R / L)^2 u.

Inverse bilinear (s, t), q0 -> (0, 0), q1 -> (1, 0), q2 -> (1, 1), q3 -> (0, 1):

- ``inverse_bilinear_textbook``: k2 t^2 + k1 t + k0 = 0 solved by
  (-k1 +- sqrt(k1^2 - 4 k2 k0)) / (2 k2): loses every digit as k2 -> 0 (a
  near-parallelogram) and divides by zero at an exact one.
- ``inverse_bilinear_thresholded``: the bilinear-from-triangle-barycentrics
  article: (s, t) from the barycentrics (beta, gamma) of p in (q0, q1, q3) by
  two quadratics whose leading coefficients are set to 0 below the absolute
  threshold 1e-5, which is right at one scale only.

Of two solutions, the one nearest the unit square (for the article, of each
parameter's two roots the one nearest [0, 1]) is taken, as in the project's
form, so that the arithmetic is what differs.
"""

from __future__ import annotations

import functools

import numpy as np

from render.coords import NEXT, PREV, Diagonals, mean_value_from_terms

#: Bloomenthal 2022, Listing 2: ``abs(A) < 1e-6 ? 0 : ...``
GUARD_AREA = 1e-6
#: The bilinear article: ``abs(A_u) < 0.00001 ? 0.0 : A_u``
ARTICLE_THRESHOLD = 1e-5


def _quiet(function):
    """The naive forms overflow and divide by zero by design: evaluate them without warnings."""

    @functools.wraps(function)
    def quiet(*args, **kwargs):
        with np.errstate(all="ignore"):
            return function(*args, **kwargs)

    return quiet


@_quiet
def mean_value_acos(p, quad, w=None) -> np.ndarray:
    """Mean value coordinates (N, 4) with angles from acos of the normalised dot product."""
    return _mean_value_from_tangents(p, quad, w, _acos_tangents)


@_quiet
def mean_value_guarded(p, quad, w=None) -> np.ndarray:
    """Mean value coordinates (N, 4) by Bloomenthal's Listing 2 (absolute guard on A_i)."""
    return _mean_value_from_tangents(p, quad, w, _guarded_tangents)


@_quiet
def mean_value_cross_area(p, quad, w=None) -> np.ndarray:
    """Mean value coordinates (N, 4): the project's tangents, A_i = s_i x s_{i+1}."""
    s, w = _offsets(p, quad, w)
    sx, sy = s[..., 0], s[..., 1]
    r = np.hypot(sx, sy)
    A = sx * sy[NEXT] - sy * sx[NEXT]
    D = sx * sx[NEXT] + sy * sy[NEXT]
    # The diagonal terms from the offsets too: edges s_{i+1} - s_i, not q_{i+1} - q_i.
    diagonals = Diagonals(sx, sy, sx[NEXT] - sx, sy[NEXT] - sy)
    if w is not None:  # the homogeneous terms, as in render.coords.mean_value
        ww = w * w[NEXT]
        r, A, D = np.abs(w) * r, ww * A, ww * D
        diagonals = Diagonals(diagonals.sx, diagonals.sy, diagonals.ex, diagonals.ey, w[PREV] * w[NEXT])
    return mean_value_from_terms(r, A, D, diagonals).T


def _offsets(p, quad, w):
    """s_i = q_i - p (4, N, 2) and w (4, 1) or None, in the inputs' float dtype."""
    p, quad = np.asarray(p), np.asarray(quad)
    dtype = np.result_type(p, quad, np.float32)
    s = quad.astype(dtype)[:, None, :] - p.astype(dtype)[None]
    return s, None if w is None else np.asarray(w, dtype=dtype)[:, None]


def _mean_value_from_tangents(p, quad, w, tangents):
    """HT04's pseudocode with the given tan(alpha_i / 2): mu_i = (t_{i-1} + t_i) / r_i,
    lambda_i = mu_i / sum_j mu_j, then with w divided by w_i and normalised (eq. 10)."""
    s, w = _offsets(p, quad, w)
    sign = np.ones((4, 1), dtype=s.dtype) if w is None else np.sign(w)
    r = np.hypot(s[..., 0], s[..., 1]) * sign  # eq. 11: signed behind the eye
    A = s[..., 0] * s[NEXT, :, 1] - s[..., 1] * s[NEXT, :, 0]
    D = s[..., 0] * s[NEXT, :, 0] + s[..., 1] * s[NEXT, :, 1]
    t = tangents(r, A, D, sign)
    mu = (t[PREV] + t) / r
    lam = mu / mu.sum(axis=0)
    if w is not None:
        lam = lam / w
        lam = lam / lam.sum(axis=0)
    return lam.T


def _acos_tangents(r, A, D, sign):
    cosine = np.clip(D / np.abs(r * r[NEXT]), -1, 1)
    alpha = np.sign(A) * np.arccos(cosine)
    alpha = np.where(sign != sign[NEXT], alpha + np.pi, alpha)  # exterior angle
    return np.tan(alpha / 2)


def _guarded_tangents(r, A, D, sign):
    return np.where(np.abs(A) < GUARD_AREA, 0, (r * r[NEXT] - D) / A)


@_quiet
def inverse_bilinear_textbook(p, quad) -> np.ndarray:
    """(s, t) (N, 2) by the textbook quadratic formula for t, then s."""
    s, _ = _offsets(p, quad, None)
    a, b, c = s[0], s[1] - s[0], s[3] - s[0]
    d = s[0] - s[1] + s[2] - s[3]
    candidates = []
    for t in _quadratic_roots(_cross(c, d), _cross(a, d) + _cross(c, b), _cross(a, b)):
        u = b + t[:, None] * d  # dP/ds
        k = np.argmax(np.abs(u), axis=1)[:, None]  # the better-determined component
        v = a + t[:, None] * c
        candidates.append(np.stack([-np.take_along_axis(v, k, 1)[:, 0] / np.take_along_axis(u, k, 1)[:, 0], t], 1))
    return _nearest_unit(candidates)


@_quiet
def inverse_bilinear_thresholded(p, quad) -> np.ndarray:
    """(s, t) (N, 2) by the bilinear article's quadratics with its absolute threshold.

    With R = q1 - q0, P = q3 - q0, Q = q2 - q1 - q3 + q0 and p - q0 = beta R +
    gamma P: A_u = R x Q, A_v = P x Q, B = P x R, and
    A_u s^2 - (beta A_u + gamma A_v + B) s + beta B = 0,
    A_v t^2 + (B - beta A_u - gamma A_v) t - gamma B = 0.
    """
    s, _ = _offsets(p, quad, None)
    h = -s[0]  # p - q0
    R, P = s[1] - s[0], s[3] - s[0]
    Q = s[2] - s[1] - s[3] + s[0]
    beta = _cross(h, P) / _cross(R, P)
    gamma = _cross(R, h) / _cross(R, P)
    A_u, A_v, B = _cross(R, Q), _cross(P, Q), _cross(P, R)
    A_u = np.where(np.abs(A_u) < ARTICLE_THRESHOLD, 0, A_u)
    A_v = np.where(np.abs(A_v) < ARTICLE_THRESHOLD, 0, A_v)
    k1_u, k1_v = -(beta * A_u + gamma * A_v + B), B - beta * A_u - gamma * A_v
    s_ = _nearest_unit([x[:, None] for x in _quadratic_roots(A_u, k1_u, beta * B)])[:, 0]
    t = _nearest_unit([x[:, None] for x in _quadratic_roots(A_v, k1_v, -gamma * B)])[:, 0]
    s_ = np.where(A_u != 0, s_, -beta * B / k1_u)
    t = np.where(A_v != 0, t, gamma * B / k1_v)
    return np.stack([s_, t], axis=1)


def _quadratic_roots(k2, k1, k0):
    """The roots (-k1 +- sqrt(k1^2 - 4 k2 k0)) / (2 k2) of k2 x^2 + k1 x + k0 = 0, (N,) each."""
    root = np.sqrt(k1 * k1 - 4 * k2 * k0)
    return (-k1 + root) / (2 * k2), (-k1 - root) / (2 * k2)


def _nearest_unit(candidates):
    """Per row, the candidate (N, K) least outside the unit cube [0, 1]^K (max norm)."""
    x = np.stack(candidates)  # (C, N, K)
    outside = np.maximum(-x, x - 1).max(axis=2)
    outside = np.where(np.isnan(outside), np.inf, outside)
    return np.take_along_axis(x, np.argmin(outside, axis=0)[None, :, None], axis=0)[0]


def _cross(u, v):
    """z of u x v for (N, 2) arrays."""
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
