"""Exact results with mpmath: mean value coordinates and inverse bilinear parameters.

The references are computed from the float inputs as given (a float is an exact
rational number): the offsets s_i = q_i - p are formed without rounding, and
everything after that runs at ``DIGITS`` significant digits. Each reference
is checked by a second, independent evaluation (``check_mean_value``,
``check_inverse_bilinear``) before it is used.

Mean value coordinates follow Hormann & Tarini 2004 (HT04): the angles alpha_i
at p in the triangles [p, q_i, q_{i+1}] come from ``atan2(A_i, D_i)``, the
weights are mu_i = (tan(alpha_{i-1} / 2) + tan(alpha_i / 2)) / r_i (eq. 8),
normalised (eq. 7); with homogeneous coordinates w_i they are divided by w_i
and normalised again (eq. 10), and a corner with w_i < 0 takes the signed
distance r_i = -|s_i| and exterior angles alpha_i + pi (eq. 11). At a corner
and exactly on an edge the limits are used, as ``render.coords`` documents.

The inverse bilinear parameters (s, t) solve P(s, t) = p for the patch
P(s, t) = (1-s)(1-t) q0 + s(1-t) q1 + s t q2 + (1-s) t q3 (design.md). A point
generally has two solutions; the reference is the one closest to the unit
square (max norm), and it must be unambiguous: the other solution lies
outside the square and farther from it by at least ``ROOT_MARGIN``.
"""

from __future__ import annotations

import mpmath

DIGITS = 60
#: The second evaluation of mean value coordinates runs at more digits, without angles.
CHECK_DIGITS = 90
#: Relative agreement required between a reference and its second evaluation.
CHECK_AGREEMENT = mpmath.mpf(10) ** -40
#: How much farther from the unit square the rejected bilinear solution must be.
ROOT_MARGIN = 1e-6


class Undefined(ValueError):
    """The exact result does not exist, or is not unique, at this point."""


def offsets(p, quad):
    """The exact offsets s_i = q_i - p as mpf pairs.

    p : (2,) float; quad : (4, 2) float. Returns a list of 4 (x, y) mpf tuples.
    """
    px, py = (mpmath.mpf(float(v)) for v in p)
    return [
        (mpmath.fsub(float(x), px, exact=True), mpmath.fsub(float(y), py, exact=True)) for x, y in quad
    ]


def homogeneous(w):
    """w_i as 4 mpf (None stays None). w : None or (4,) float."""
    return None if w is None else [mpmath.mpf(float(v)) for v in w]


def mean_value_exact(s, w=None):
    """HT04 eq. 7, 8 (and 10, 11 with ``w``) at ``DIGITS`` digits, angles by atan2.

    s : 4 (x, y) mpf pairs, s_i = q_i - p; w : None or 4 nonzero mpf (``homogeneous``).
    Returns the 4 weights (mpf), summing to 1. Raises ``Undefined`` where the
    weights have no value (sum of mu_i zero).
    """
    with mpmath.workdps(DIGITS):
        return _mean_value(s, w, _angle_tangents)


def mean_value_algebraic(s, w=None):
    """The same weights a second way: tan(alpha_i / 2) = (r_i r_{i+1} - D_i) / A_i,
    or A_i / (r_i r_{i+1} + D_i) where A_i = 0, at ``CHECK_DIGITS`` digits."""
    with mpmath.workdps(CHECK_DIGITS):
        return _mean_value(s, w, _algebraic_tangents)


def _mean_value(s, w, tangents):
    sign = [1] * 4 if w is None else [1 if v > 0 else -1 for v in w]
    r = [mpmath.hypot(x, y) for x, y in s]
    for i in range(4):
        if r[i] == 0:
            return [mpmath.mpf(int(i == k)) for k in range(4)]
    following = [s[(i + 1) % 4] for i in range(4)]
    A = [a[0] * b[1] - a[1] * b[0] for a, b in zip(s, following)]
    D = [a[0] * b[0] + a[1] * b[1] for a, b in zip(s, following)]
    absw = [mpmath.mpf(1)] * 4 if w is None else [abs(v) for v in w]
    for i in range(4):
        j = (i + 1) % 4
        if A[i] == 0 and sign[i] * sign[j] * D[i] < 0:  # on edge i: the linear (perspective) limit
            lam = [mpmath.mpf(0)] * 4
            lam[i] = absw[j] * r[j] / (absw[j] * r[j] + absw[i] * r[i])
            lam[j] = absw[i] * r[i] / (absw[j] * r[j] + absw[i] * r[i])
            return lam
    t = tangents(r, A, D, sign)
    mu = [(t[i - 1] + t[i]) / (sign[i] * r[i]) for i in range(4)]
    if w is not None:
        mu = [m / v for m, v in zip(mu, w)]
    total = mpmath.fsum(mu)
    if total == 0:
        raise Undefined("the mean value weights sum to zero")
    return [m / total for m in mu]


def _angle_tangents(r, A, D, sign):
    t = []
    for i in range(4):
        alpha = mpmath.atan2(A[i], D[i])
        if sign[i] != sign[(i + 1) % 4]:
            alpha += mpmath.pi  # exterior angle (HT04 section 3.2)
        t.append(mpmath.tan(alpha / 2))
    return t


def _algebraic_tangents(r, A, D, sign):
    t = []
    for i in range(4):
        rr = sign[i] * sign[(i + 1) % 4] * r[i] * r[(i + 1) % 4]
        t.append((rr - D[i]) / A[i] if A[i] != 0 else A[i] / (rr + D[i]))
    return t


def check_mean_value(s, w, lam):
    """Raise ``AssertionError`` unless ``lam`` (from ``mean_value_exact``) matches
    ``mean_value_algebraic`` and reproduces the point: sum_i lambda_i w_i s_i = 0
    (linear precision, homogeneous form) and sum_i lambda_i = 1."""
    second = mean_value_algebraic(s, w)
    with mpmath.workdps(DIGITS):
        size = max(1, max(abs(v) for v in lam))
        _require(max(abs(a - b) for a, b in zip(lam, second)) <= CHECK_AGREEMENT * size, "two evaluations differ")
        _require(abs(mpmath.fsum(lam) - 1) <= CHECK_AGREEMENT * size, "no partition of unity")
        ww = [mpmath.mpf(1)] * 4 if w is None else w
        for k in range(2):
            terms = [lam[i] * ww[i] * s[i][k] for i in range(4)]
            bound = mpmath.fsum(abs(v) for v in terms)
            _require(abs(mpmath.fsum(terms)) <= CHECK_AGREEMENT * bound, "no linear precision")


def inverse_bilinear_exact(s, near=None):
    """(s, t) with P(s, t) = p, at ``DIGITS`` digits.

    s : 4 (x, y) mpf pairs, s_i = q_i - p. ``near``: None to take the solution
    closest to the unit square (raising ``Undefined`` when that choice is not
    clear by ``ROOT_MARGIN``), or an (s, t) pair to take the solution closest
    to it (to follow one solution under small changes of the input).
    Returns (s, t) as mpf. Raises ``Undefined`` where no real solution exists.

    With a = s_0, b = s_1 - s_0, c = s_3 - s_0, d = s_0 - s_1 + s_2 - s_3,
    P(s, t) - p = a + s b + t c + s t d; eliminating s leaves
    k2 t^2 + k1 t + k0 = 0 with k2 = c x d, k1 = a x d + c x b, k0 = a x b.
    """
    with mpmath.workdps(DIGITS):
        a, b, c, d = _bilinear_vectors(s)
        k2 = _cross(c, d)
        k1 = _cross(a, d) + _cross(c, b)
        k0 = _cross(a, b)
        disc = k1 * k1 - 4 * k2 * k0
        if disc < 0:
            raise Undefined("P(s, t) = p has no real solution")
        # Q = -(k1 + sign(k1) sqrt(disc)) / 2 does not cancel: t = k0 / Q and Q / k2
        # keep all digits also when k2 is 10^-30 of k1 (a near-parallelogram).
        Q = -(k1 + mpmath.sign(k1) * mpmath.sqrt(disc)) / 2 if k1 != 0 else mpmath.sqrt(-k2 * k0)
        ts = [t for t in (k0 / Q if Q != 0 else None, Q / k2 if k2 != 0 else None) if t is not None]
        candidates = []
        for t in ts:
            ux, uy = b[0] + t * d[0], b[1] + t * d[1]
            uu = ux * ux + uy * uy
            if uu != 0:  # else every s gives the same point: the collapsed edge of a pole
                candidates.append((-(ux * (a[0] + t * c[0]) + uy * (a[1] + t * c[1])) / uu, t))
        if not candidates:
            raise Undefined("no solution with a unique s")
        if near is not None:
            return min(candidates, key=lambda st: max(abs(st[0] - near[0]), abs(st[1] - near[1])))
        candidates.sort(key=_outside_unit_square)
        if len(candidates) > 1 and (
            _outside_unit_square(candidates[1]) <= 0
            or _outside_unit_square(candidates[1]) - _outside_unit_square(candidates[0]) < ROOT_MARGIN
        ):
            raise Undefined("two solutions are equally close to the unit square")
        return candidates[0]


def check_inverse_bilinear(s, st):
    """Raise ``AssertionError`` unless (s, t) maps back to p: the residual
    a + s b + t c + s t d vanishes relative to the size of its terms."""
    with mpmath.workdps(DIGITS):
        a, b, c, d = _bilinear_vectors(s)
        u, t = st
        for k in range(2):
            terms = [a[k], u * b[k], t * c[k], u * t * d[k]]
            bound = mpmath.fsum(abs(v) for v in terms)
            _require(abs(mpmath.fsum(terms)) <= CHECK_AGREEMENT * bound, "P(s, t) is not p")


def _require(holds, message):
    """An ``AssertionError`` that ``python -O`` keeps."""
    if not holds:
        raise AssertionError(message)


def _bilinear_vectors(s):
    (s0, s1, s2, s3) = s
    a = s0
    b = (s1[0] - s0[0], s1[1] - s0[1])
    c = (s3[0] - s0[0], s3[1] - s0[1])
    d = (s0[0] - s1[0] + s2[0] - s3[0], s0[1] - s1[1] + s2[1] - s3[1])
    return a, b, c, d


def _cross(u, v):
    return u[0] * v[1] - u[1] * v[0]


def _outside_unit_square(st):
    return max(-st[0], st[0] - 1, -st[1], st[1] - 1)
