"""Generalised barycentric coordinates of points in a quadrilateral.

Two coordinate systems, vectorised over N points:

- ``mean_value``: the mean value coordinates of Hormann & Tarini 2004 (HT04),
  eq. 7 with the eq. 8 weights, and with ``w`` the perspective coordinates of
  eq. 10 with the signed distances of eq. 11 for corners behind the eye.
- ``inverse_bilinear``: the parameters (s, t) of the bilinear patch through the
  four corners (Bloomenthal 2022, section 3.3).

Both are written for float64 robustness (see issue 11): everything is formed
from ``q_i - p`` first, tolerances are relative, points on an edge or at a
corner get their exact value, and degenerate quads give finite results.

The rasterizer evaluates mean value coordinates from clip-space corners through
the same two steps, ``mean_value_terms`` then ``mean_value_from_terms``.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

NEXT = np.array([1, 2, 3, 0])
PREV = np.array([3, 0, 1, 2])

# Used only where the general formula gives inf or NaN: |A_i| <= EDGE_SINE *
# r_i r_{i+1} with D_i < 0 means sin(alpha_i) < 2^-60, the point is on edge i
# to within rounding and the edge value is exact far below float64 precision;
# r_i = 0 means the point is at corner i.
EDGE_SINE = 2.0**-60
NEWTON_STEPS = 2
# inverse_bilinear's frames: FRAMES[k] renumbers the corners so that corner k
# comes first, keeping the patch (q0, q1, q2, q3 at (0,0), (1,0), (1,1), (0,1));
# FLIPS_S[k] / FLIPS_T[k]: the frame's s / t is 1 - s / 1 - t.
FRAMES = np.array([[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]])
FLIPS_S = np.array([False, True, True, False])
FLIPS_T = np.array([False, False, True, True])


def mean_value(p, quad, w=None) -> np.ndarray:
    """Mean value coordinates of points ``p`` in the screen quad ``quad`` (HT04).

    Parameters
    ----------
    p : (N, 2) float
        Query points.
    quad : (4, 2) or (N, 4, 2) float
        Screen corners q_0..q_3 (one quad for all points, or one per point).
    w : None, (4,) or (N, 4) float, nonzero
        Homogeneous corner coordinates w_i. Without ``w``: the plain
        coordinates lambda_i = mu_i / sum_j mu_j (eq. 7, eq. 8). With ``w``:
        the perspective coordinates lambda'_i = (lambda_i / w_i) /
        sum_j (lambda_j / w_j) (eq. 10), where a corner with w_i < 0 (behind
        the eye) takes the signed distance r_i = sign(w_i) |s_i| (eq. 11).
        Corners with w_i = 0 have no screen position: clip-space quads are the
        rasterizer's job, here they raise ``ValueError``.

    Returns
    -------
    lam : (N, 4) float64
        Weights summing to 1 (float32, computed in float32, when ``p`` and
        ``quad`` are float32 arrays). A point on edge i gets the linear weights of
        that edge (exactly where A_i evaluates to 0, else to rounding), a
        point at corner i the unit vector e_i.

    Notes
    -----
    Degenerate input gives finite, documented values: a repeated corner or a
    collapsed edge is handled by the formulas themselves (its tangent term is
    exactly 0); where the weights are not defined (sum of mu_i exactly 0 or
    not finite, e.g. a point on the line of a zero-area quad outside it) the
    point gets the unit weight of its nearest corner. At the crossing point of
    a bow-tie, which lies on two edges, the lower-numbered edge is used.

    Examples
    --------
    >>> square = [[0, 0], [1, 0], [1, 1], [0, 1]]
    >>> mean_value([[0.5, 0.5], [0.25, 0.0]], square).round(12).tolist()
    [[0.25, 0.25, 0.25, 0.25], [0.75, 0.25, 0.0, 0.0]]
    """
    p, q = _points_and_corners(p, quad)
    s = q - p  # (4, N, 2): q_i - p before anything else
    e = q[NEXT] - q  # edge vectors q_{i+1} - q_i from the corners themselves
    # The coordinates do not change when all s_i scale together: work at unit
    # scale so that r^2, A and D neither overflow nor underflow.
    scale = np.abs(s).max(axis=(0, 2))
    scale[scale == 0] = 1.0
    s = s / scale[:, None]
    e = e / scale[:, None]
    r, A, D, diagonals = mean_value_terms(s[..., 0], s[..., 1], e[..., 0], e[..., 1])
    if w is not None:
        w = _corner_weights(w, p.shape[0], p.dtype)
        # r~ = |w_i| r_i, A~ = w_i w_{i+1} A_i, D~ = w_i w_{i+1} D_i (and the
        # diagonal terms with w_{i-1} w_{i+1}) are the terms of s~_i = w_i s_i
        # and give exactly the eq. 10 weights with the eq. 11 signs (see
        # mean_value_from_terms); the common scale of w cancels.
        w = w / np.abs(w).max(axis=0)
        ww = w * w[NEXT]
        r, A, D = np.abs(w) * r, ww * A, ww * D
        diagonals = dataclasses.replace(diagonals, weight=w[PREV] * w[NEXT])
    return mean_value_from_terms(r, A, D, diagonals).T


def _cyclic(ufunc, a, b, shift, dtype=None):
    """``ufunc(a_i, b_{i + shift})`` for corner-major arrays (4, ...), i cyclic, shift 1 or -1.

    Formed from slices of ``b``: ``b[NEXT]`` would first copy all of it. The same values as
    ``ufunc(a, b[NEXT])`` (shift 1) or ``ufunc(a, b[PREV])`` (shift -1), bit for bit, of
    ``dtype`` (default: that of a and b).
    """
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype or np.result_type(a, b))
    if shift == 1:
        ufunc(a[:3], b[1:], out=out[:3])
        ufunc(a[3], b[0], out=out[3])
    else:
        ufunc(a[1:], b[:3], out=out[1:])
        ufunc(a[0], b[3], out=out[0])
    return out


def mean_value_terms(sx, sy, ex, ey):
    """The per-corner terms r_i, A_i, D_i of HT04 section 4.2, and the diagonal terms.

    Parameters
    ----------
    sx, sy : (4, N) float64
        Components of s_i = q_i - p (or of the homogeneous s~_i = X_i - p W_i).
    ex, ey : (4, N) or (4, 1) float64
        Components of the edge vector s_{i+1} - s_i, computed by the caller
        from the corners themselves (q_{i+1} - q_i), not from the s_i.

    Returns
    -------
    r : (4, N) float64
        |s_i|.
    A : (4, N) float64
        s_i x s_{i+1} (twice the signed area of the triangle [p, q_i, q_{i+1}]),
        evaluated as (the shorter of s_i, s_{i+1}) x e_i: for a point far
        from a short edge the product of two long, nearly parallel vectors
        would lose (R/L)^2 of the precision, the edge form keeps R/L.
    D : (4, N) float64
        s_i . s_{i+1}.
    diagonals : Diagonals
        C_i = s_{i-1} x s_{i+1} and E_i = s_{i-1} . s_{i+1}, formed on demand.
    """
    sxn, syn = sx[NEXT], sy[NEXT]
    r = sx * sx
    r += sy * sy
    np.sqrt(r, out=r)
    D = sx * sxn
    D += sy * syn
    shorter = _cyclic(np.less_equal, r, r, 1, bool)
    A = np.where(shorter, sx, sxn) * ey
    A -= np.where(shorter, sy, syn) * ex
    return r, A, D, Diagonals(sx, sy, ex, ey)


@dataclasses.dataclass(frozen=True)
class Diagonals:
    """The diagonal terms of ``mean_value_terms``, formed only for the points
    that need them (those where some alpha_{i-1}, alpha_i have opposite signs,
    see ``mean_value_from_terms``).

    sx, sy : (4, N) and ex, ey : (4, N) or (4, 1), as given to
    ``mean_value_terms``; weight : None or (4, N) or (4, 1), w_{i-1} w_{i+1}
    for the perspective terms of ``mean_value``.
    """

    sx: np.ndarray
    sy: np.ndarray
    ex: np.ndarray
    ey: np.ndarray
    weight: np.ndarray | None = None

    def terms(self, cols):
        """C, E, G (4, M) float64 of the points ``cols`` (M,) int.

        C_i = s_{i-1} x s_{i+1}, as u x d with u the shorter of the two and
        d = e_{i-1} + e_i = q_{i+1} - q_{i-1}, for the same reason as A;
        E_i = s_{i-1} . s_{i+1}; G_i = |u_x| (|ey_{i-1}| + |ey_i|) +
        |u_y| (|ex_{i-1}| + |ex_i|), the size of the terms C is formed from
        (d included), so that its rounding error is about u G. With a weight,
        C and E are multiplied by it and G by its absolute value.
        """
        sx, sy = self.sx[:, cols], self.sy[:, cols]
        ex, ey = (v if v.shape[1] == 1 else v[:, cols] for v in (self.ex, self.ey))
        sxp, syp, sxn, syn = sx[PREV], sy[PREV], sx[NEXT], sy[NEXT]
        shorter = sxp * sxp + syp * syp <= sxn * sxn + syn * syn
        ux, uy = np.where(shorter, sxp, sxn), np.where(shorter, syp, syn)
        C = ux * (ey[PREV] + ey) - uy * (ex[PREV] + ex)
        E = sxp * sxn + syp * syn
        G = np.abs(ux) * (np.abs(ey[PREV]) + np.abs(ey)) + np.abs(uy) * (np.abs(ex[PREV]) + np.abs(ex))
        if self.weight is None:
            return C, E, G
        wd = self.weight if self.weight.shape[1] == 1 else self.weight[:, cols]
        return wd * C, wd * E, np.abs(wd) * G


def mean_value_from_terms(r, A, D, diagonals) -> np.ndarray:
    """Normalised mean value weights from the terms r, A, D (HT04 eq. 7, 8).

    With t_i = tan(alpha_i / 2), mu_i = (t_{i-1} + t_i) / r_i (eq. 8) and
    lambda_i = mu_i / sum_j mu_j (eq. 7). Of the two equal forms
    t_i = (r_i r_{i+1} - D_i) / A_i = A_i / (r_i r_{i+1} + D_i) the first
    cancels for small angles (far points, needles) and the second near an
    edge (alpha_i near pi); the form is chosen by the sign of r_i r_{i+1} D_i.

    Where alpha_{i-1} and alpha_i have opposite signs the sum t_{i-1} + t_i
    cancels when they nearly balance: near the sharp tip q_i of a needle,
    whose neighbours p sees in almost the same direction, both are O(1) and
    the sum is the tip's angle. There it is taken as
    sin(gamma_i / 2) / (cos(alpha_{i-1} / 2) cos(alpha_i / 2)), with
    gamma_i = alpha_{i-1} + alpha_i the angle from s_{i-1} to s_{i+1} (in
    (-pi, pi) for opposite signs): each factor has a form that does not
    cancel, cos(alpha / 2) = sqrt(h / 2 r r') for D >= 0 and |A| / sqrt(2 r r' h)
    for D < 0 (h = r r' + |D|), and sin(gamma / 2) from the diagonal terms
    C, E alike. Of the two, the one with the smaller rounding is taken: the
    plain sum loses max(|t_{i-1}|, |t_i|) / |t_{i-1} + t_i| ulps, this form
    G / |C| (C itself cancels where p is near the line through q_{i-1} and
    q_{i+1}).

    Perspective (eq. 10, 11) enters only through the terms: with
    r_i = |w_i||s_i|, A_i = w_i w_{i+1} (s_i x s_{i+1}) and
    D_i = w_i w_{i+1} (s_i . s_{i+1}) -- which is what the homogeneous vectors
    s~_i = w_i (q_i - p) = X_i - p W_i give -- the common factor w_i w_{i+1}
    cancels in t_i except for its sign, which is that of eq. 11
    (sign(w_i) sign(w_{i+1}) r_i r_{i+1}), and mu_i / r_i carries 1 / |w_i|
    where eq. 10 divides by w_i and eq. 11 by sign(w_i). So these weights are
    the perspective lambda'_i. Since every r_i >= 0 here, the sign of
    r_i r_{i+1} D_i is the sign of D_i.

    Parameters
    ----------
    r, A, D : (4, N) float64
        As returned by ``mean_value_terms``, possibly scaled by w (above).
    diagonals : Diagonals
        As returned by ``mean_value_terms`` (with its weight, if scaled).

    Returns
    -------
    lam : (4, N) float64
        Corner-major weights, each column summing to 1. Near an edge or a
        corner the formulas stay accurate (t_i or 1 / r_i grows, lambda tends
        to its limit); where they give inf or NaN -- exactly on edge i
        (A_i = 0, D_i < 0), exactly at corner i (r_i = 0), or where eq. 7 has
        no value -- the exact limits are used: lambda_i = r_{i+1} / (r_i +
        r_{i+1}), lambda_{i+1} = r_i / (r_i + r_{i+1}) on the edge, the unit
        vector e_i at the corner, and the unit vector of the nearest corner
        where sum_j mu_j is 0 or not finite.
    """
    rr = _cyclic(np.multiply, r, r, 1)
    h = np.abs(D)
    h += rr  # r_i r_{i+1} + |D_i|: never cancels
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        acute = D > 0
        t = np.where(acute, A, h)
        t /= np.where(acute, h, A)
        summed = _cyclic(np.add, t, t, -1)
        cols = np.flatnonzero((_cyclic(np.multiply, A, A, -1) < 0).any(axis=0))
        if cols.size:
            sub = (slice(None), cols)
            summed[sub] = _balanced_sums(r[sub], A[sub], D[sub], rr[sub], h[sub], t[sub], *diagonals.terms(cols))
        mu = summed / r
        total = mu.sum(axis=0)
        lam = mu / total
    cols = np.flatnonzero(~np.isfinite(total) | (total == 0))
    if cols.size:
        lam[:, cols] = _exact_special_weights(r[:, cols], A[:, cols], D[:, cols])
    return lam


def _balanced_sums(r, A, D, rr, h, t, C, E, G):
    """t_{i-1} + t_i (4, M), by the half-angle form where alpha_{i-1} and alpha_i
    have opposite signs and it rounds less (see mean_value_from_terms)."""
    summed = t[PREV] + t
    better = (A[PREV] * A < 0) & (G * np.abs(summed) < np.abs(C) * np.maximum(np.abs(t[PREV]), np.abs(t)))
    root2rr, root_h = np.sqrt(2 * rr), np.sqrt(h)
    half_cos = np.where(D >= 0, root_h / root2rr, np.abs(A) / (root2rr * root_h))  # cos(alpha_i / 2)
    rho = r[PREV] * r[NEXT]
    root2rho, root_g = np.sqrt(2 * rho), np.sqrt(rho + np.abs(E))
    half_sin = np.where(E >= 0, C / (root2rho * root_g), np.copysign(root_g / root2rho, C))  # sin(gamma_i / 2)
    return np.where(better, half_sin / (half_cos[PREV] * half_cos), summed)


def _exact_special_weights(r, A, D) -> np.ndarray:
    """Weights for points at a corner, on an edge, or where eq. 7 is undefined.

    r, A, D : (4, M). Returns (4, M) float64.
    """
    m = r.shape[1]
    cols = np.arange(m)
    on_edge = (D < 0) & (np.abs(A) <= EDGE_SINE * r * r[NEXT])
    lam = np.zeros_like(r)
    lam[np.argmin(r, axis=0), cols] = 1.0  # corner, or the documented fallback
    # The edge value also holds next to its corners (it tends to e_i there); an
    # exact corner (r_i = 0) keeps e_i even where a degenerate quad puts it on
    # another edge. (r is |w_i| |s_i| with w, so "small" would depend on w.)
    edge = on_edge.any(axis=0) & ~(r == 0).any(axis=0)
    i = np.argmax(on_edge[:, edge], axis=0)
    j = NEXT[i]
    c = cols[edge]
    ri, rj = r[i, c], r[j, c]
    lam[:, edge] = 0.0
    lam[i, c] = rj / (ri + rj)
    lam[j, c] = ri / (ri + rj)
    return lam


def inverse_bilinear(p, quad) -> np.ndarray:
    """Parameters (s, t) of points ``p`` on the bilinear patch through ``quad``.

    The patch is P(s, t) = (1-s)(1-t) q0 + s(1-t) q1 + s t q2 + (1-s) t q3, so
    q0 -> (0, 0), q1 -> (1, 0), q2 -> (1, 1), q3 -> (0, 1). The (s, t) have no
    partition-of-unity property; ``bilinear_weights`` turns them into corner
    weights.

    Parameters
    ----------
    p : (N, 2) float
    quad : (4, 2) or (N, 4, 2) float

    Returns
    -------
    st : (N, 2) float64
        (float32, computed in float32, when ``p`` and ``quad`` are float32 arrays)

    Notes
    -----
    The patch is solved in the frame of the corner nearest to p: the corners
    are renumbered so that it is q0 (and s -> 1 - s, t -> 1 - t where that
    flips the axes), so the unknowns are small near it and carry relative
    precision, and the terms of the residual below are as small as p's
    offsets from the nearby corners (near the collapsed edge of a pole quad
    they are otherwise long vectors that cancel, and s loses L / delta of
    its digits at a distance delta from the pole).
    With a = q0 - p (translated to the point first), b = q1 - q0, c = q3 - q0,
    d = q0 - q1 + q2 - q3, P(s, t) = p reads a + s b + t c + s t d = 0, and
    eliminating s gives k2 t^2 + k1 t + k0 = 0 with k2 = c x d,
    k1 = a x d + c x b, k0 = a x b. The roots are taken in the form that never
    cancels, Q = -(k1 + sign(k1) sqrt(k1^2 - 4 k2 k0)) / 2, t = k0 / Q and
    t = Q / k2: at a near-parallelogram (k2 -> 0) the first stays accurate and
    the second goes to infinity, and at an exact parallelogram nothing divides
    by zero. Of the two the root whose (s, t) lies closer to the unit square is
    kept (s from t by least squares; a root on a collapsed edge, where every s
    is the same point, only when there is no other), then safeguarded Newton
    steps on the 2-D system (a step is kept only if it lowers the residual)
    recover the digits lost where the two roots nearly meet.
    A point at a corner gets exactly that corner's (s, t) (also at the reflex
    corner of a dart, where the patch folds and a second solution exists).
    Where no real solution exists (negative discriminant: outside the patch's
    image) the discriminant is taken as 0; a row with no finite candidate
    (zero-area quad, or p on a collapsed edge) starts from the corner q0 of
    its frame. The result is always finite.

    Examples
    --------
    >>> quad = [[0, 0], [2, 0], [2, 1], [0, 1]]
    >>> inverse_bilinear([[1.0, 0.25]], quad).tolist()
    [[0.5, 0.25]]
    """
    p, q = _points_and_corners(p, quad)
    s, t = bilinear_parameters(p[:, 0], p[:, 1], q[..., 0], q[..., 1])
    return np.stack([s, t], axis=1)


def bilinear_parameters(px, py, qx, qy):
    """``inverse_bilinear`` on components: px, py (N,), qx, qy (4, N) or (4, 1).

    Returns s, t (N,) of the inputs' float dtype.
    """
    # The frame of the nearest corner (see inverse_bilinear): FRAMES[k] lists
    # the corners renumbered so that corner k is q0.
    nearest = np.argmin(np.maximum(np.abs(qx - px), np.abs(qy - py)), axis=0)
    order = FRAMES[nearest].T  # (4, N)
    qx = np.take_along_axis(np.broadcast_to(qx, order.shape), order, axis=0)
    qy = np.take_along_axis(np.broadcast_to(qy, order.shape), order, axis=0)
    a = (qx[0] - px, qy[0] - py)  # translated to the point first
    b = (qx[1] - qx[0], qy[1] - qy[0])
    c = (qx[3] - qx[0], qy[3] - qy[0])
    d = ((qx[2] - qx[3]) - b[0], (qy[2] - qy[3]) - b[1])
    scale = functools.reduce(np.maximum, [np.abs(v) for v in (*a, *b, *c, *d)])
    scale[scale == 0] = 1.0
    a, b, c, d = ((x / scale, y / scale) for x, y in (a, b, c, d))
    k2 = cross2(c, d)
    k1 = cross2(a, d) + cross2(c, b)
    k0 = cross2(a, b)
    root = np.sqrt(np.maximum(k1 * k1 - 4.0 * k2 * k0, 0.0))
    Q = -0.5 * (k1 + np.copysign(root, k1))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t_near, t_far = k0 / Q, Q / k2
        s_near, s_far = s_given_t(a, b, c, d, t_near), s_given_t(a, b, c, d, t_far)
    far = _outside_unit_square(s_far, t_far) < _outside_unit_square(s_near, t_near)
    s, t = np.where(far, s_far, s_near), np.where(far, t_far, t_near)
    # p at the frame's corner q0 (a = 0) gets exactly (0, 0): the Lagrange property,
    # also where the patch folds over a reflex corner and another root exists.
    start_at_corner = ~(np.isfinite(s) & np.isfinite(t)) | ((a[0] == 0) & (a[1] == 0))
    s[start_at_corner] = 0.0
    t[start_at_corner] = 0.0
    for _ in range(NEWTON_STEPS):
        s, t = newton_step(a, b, c, d, s, t)
    return np.where(FLIPS_S[nearest], 1 - s, s), np.where(FLIPS_T[nearest], 1 - t, t)


def bilinear_weights(s, t) -> np.ndarray:
    """Corner weights (4, N) of the bilinear patch at parameters s, t (N,):
    ((1-s)(1-t), s(1-t), s t, (1-s) t), corner-major."""
    return np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t])


def s_given_t(a, b, c, d, t):
    """Least-squares s of (a + t c) + s (b + t d) = 0; NaN where b + t d = 0
    (a collapsed edge, every s the same point). Components (N,) -> (N,)."""
    ux, uy = b[0] + t * d[0], b[1] + t * d[1]  # dP/ds
    uu = ux * ux + uy * uy
    s = -(ux * (a[0] + t * c[0]) + uy * (a[1] + t * c[1])) / uu
    return np.where(uu > 0, s, np.nan)


def _outside_unit_square(s, t):
    """How far (s, t) lies outside [0, 1]^2 (max norm); inf where not finite."""
    out = np.maximum(np.maximum(-s, s - 1), np.maximum(-t, t - 1))
    return np.where(np.isfinite(out), out, np.inf)


def newton_step(a, b, c, d, s, t):
    """One safeguarded Newton step for F = a + s b + t c + s t d = 0 (components).

    The step is kept only where it lowers the backward error of ``_residual``.
    """
    F, error = _residual(a, b, c, d, s, t)
    Js = (b[0] + t * d[0], b[1] + t * d[1])
    Jt = (c[0] + s * d[0], c[1] + s * d[1])
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        det = cross2(Js, Jt)
        s1 = s + cross2(Jt, F) / det
        t1 = t + cross2(F, Js) / det
        better = _residual(a, b, c, d, s1, t1)[1] < error
    return np.where(better, s1, s), np.where(better, t1, t)


def _residual(a, b, c, d, s, t):
    """F = a + s b + t c + s t d (component pair) and its componentwise backward
    error max_k |F_k| / (|a_k| + |s b_k| + |t c_k| + |s t d_k|) (N,): each row
    relative to its own terms, so that a thin quad's short row counts as much
    as its long one (|F| alone would only see the long one)."""
    st = s * t
    F, error = [], 0.0
    for k in range(2):
        terms = (a[k], s * b[k], t * c[k], st * d[k])
        F.append(terms[0] + terms[1] + terms[2] + terms[3])
        size = np.abs(terms[0]) + np.abs(terms[1]) + np.abs(terms[2]) + np.abs(terms[3])
        relative = np.where(size > 0, np.abs(F[k]) / np.where(size > 0, size, 1), 0.0)
        error = np.maximum(error, np.where(np.isfinite(F[k]), relative, np.inf))
    return tuple(F), error


def cross2(u, v) -> np.ndarray:
    """z-component of u x v for component pairs u = (ux, uy), v = (vx, vy)."""
    return u[0] * v[1] - u[1] * v[0]


def _points_and_corners(p, quad):
    """Validate and return p (N, 2) and corner-major corners (4, N|1, 2): float32
    when both are float32 arrays (to measure the forms at GPU precision), else float64."""
    single = all(getattr(v, "dtype", None) == np.float32 for v in (p, quad))
    dtype = np.float32 if single else np.float64
    p = np.asarray(p, dtype=dtype)
    quad = np.asarray(quad, dtype=dtype)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"p must have shape (N, 2), got {p.shape}")
    if quad.shape == (4, 2):
        q = quad[:, None, :]
    elif quad.shape == (p.shape[0], 4, 2):
        q = quad.transpose(1, 0, 2)
    else:
        raise ValueError(f"quad must have shape (4, 2) or ({p.shape[0]}, 4, 2), got {quad.shape}")
    return p, q


def _corner_weights(w, n, dtype) -> np.ndarray:
    """Validate w ((4,) or (N, 4), finite, nonzero) and return it corner-major (4, N|1) of ``dtype``."""
    w = np.asarray(w, dtype=dtype)
    if w.shape == (4,):
        w = w[:, None]
    elif w.shape == (n, 4):
        w = w.T
    else:
        raise ValueError(f"w must have shape (4,) or ({n}, 4), got {w.shape}")
    if not np.all(np.isfinite(w)) or np.any(w == 0):
        raise ValueError("w must be finite and nonzero (a corner with w = 0 has no screen position)")
    return w
