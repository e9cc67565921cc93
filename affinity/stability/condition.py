"""How much a problem's exact answer moves when its inputs are rounded: the condition estimate.

A routine that computes q_i - p and w_i in floating point has, at best, each of
those inputs wrong by a relative u (the unit roundoff, 2^-53 in float64,
2^-24 in float32). No algorithm can promise more than the change that causes
in the exact result. So the estimate perturbs each input x_j -- the eight
components of s_i = q_i - p and, with homogeneous coordinates, the four w_i --
by u |x_j|, one at a time, evaluates the exact result (``reference``) for each,
and adds up the absolute changes: to first order the worst change when all
inputs move by up to u at once, i.e. u times the componentwise (Skeel)
condition number. The maximum over the result's components is taken (infinity
norm); for points far outside the quad, where weights and parameters grow
with the distance, it is divided by the largest component of the result
(relative error).

The tolerance is ``max(64 u, 16 * condition)``: 16 allows for a small
constant of a backward-stable algorithm, and 64 u keeps a floor for
well-conditioned problems, whose error is a few roundings of the arithmetic
that follows the inputs.
"""

from __future__ import annotations

import mpmath

from .reference import DIGITS
from .rows import TOLERANCE_FACTOR, TOLERANCE_FLOOR


def condition(exact, s, w, u, relative=False) -> float:
    """First-order worst change of ``exact(s, w)`` under relative perturbations u.

    Parameters
    ----------
    exact : callable (s, w) -> sequence of mpf
        The exact result, e.g. ``reference.mean_value_exact``.
    s : 4 (x, y) mpf pairs
        s_i = q_i - p.
    w : None or 4 mpf
        Homogeneous corner coordinates (``reference.homogeneous``), perturbed
        too when given.
    u : float
        Unit roundoff of the precision.
    relative : bool
        Divide by the largest component of the unperturbed result.

    Returns
    -------
    float
        sum_j |exact(x + u |x_j| e_j) - exact(x)|, max over components.
    """
    with mpmath.workdps(DIGITS):
        grow = 1 + mpmath.mpf(u)
        base = exact(s, w)
        total = [mpmath.mpf(0)] * len(base)
        for i in range(4):
            for k in range(2):
                moved = [list(v) for v in s]
                moved[i][k] = s[i][k] * grow
                _accumulate(total, base, exact(moved, w))
        if w is not None:
            for i in range(4):
                moved = list(w)
                moved[i] = w[i] * grow
                _accumulate(total, base, exact(s, moved))
        worst = max(total)
        if relative:
            worst /= max(abs(v) for v in base)
        return float(worst)


def _accumulate(total, base, moved):
    for k, (a, b) in enumerate(zip(moved, base)):
        total[k] += abs(a - b)


def tolerance(cond: float, u: float) -> float:
    """The allowed error: ``max(64 u, 16 * cond)``."""
    return max(TOLERANCE_FLOOR * u, TOLERANCE_FACTOR * cond)
