"""Run the catalogue: every case, method and precision becomes one row of the table.

For each case and precision the exact result of every point (``reference``),
checked by its second evaluation, and its tolerance (``condition``) are
computed once per quantity (mean value weights, inverse bilinear (s, t)) and
shared by that quantity's methods: the project's (``render.coords``) and the
naive forms (``naive``). float32 rows round the case's inputs to float32 and
compare with the exact result for those rounded inputs, with u = 2^-24.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from render import coords

from . import naive, properties
from .cases import Case, catalogue
from .condition import condition, tolerance
from .reference import (
    Undefined,
    check_inverse_bilinear,
    check_mean_value,
    homogeneous,
    inverse_bilinear_exact,
    mean_value_exact,
    offsets,
)
from .rows import TOLERANCE_FLOOR, UNIT_ROUNDOFF, Row

#: float64 gates the command; float32 is reported.
PRECISIONS = ("float64", "float32")


@dataclass(frozen=True)
class Method:
    """A function under test: ``function(p, quad[, w])`` -> (N, K) for one quantity."""

    name: str
    quantity: str  # "mean_value" (weights, K = 4) or "inverse_bilinear" ((s, t), K = 2)
    function: Callable
    naive: bool = False

    def __call__(self, case: Case) -> np.ndarray:
        if self.quantity == "mean_value":
            return self.function(case.points, case.quad, case.w)
        return self.function(case.points, case.quad)

    def weights(self, result) -> np.ndarray:
        """Corner weights (N, 4) float64 of a result (N, K), for the Lagrange check."""
        result = np.asarray(result, dtype=np.float64)
        if self.quantity == "mean_value":
            return result
        with np.errstate(invalid="ignore"):  # naive forms may give NaN
            return coords.bilinear_weights(result[:, 0], result[:, 1]).T


METHODS = (
    Method("mean_value", "mean_value", coords.mean_value),
    Method("inverse_bilinear", "inverse_bilinear", coords.inverse_bilinear),
    Method("naive_acos", "mean_value", naive.mean_value_acos, naive=True),
    Method("naive_guarded", "mean_value", naive.mean_value_guarded, naive=True),
    Method("naive_cross_area", "mean_value", naive.mean_value_cross_area, naive=True),
    Method("naive_textbook", "inverse_bilinear", naive.inverse_bilinear_textbook, naive=True),
    Method("naive_thresholded", "inverse_bilinear", naive.inverse_bilinear_thresholded, naive=True),
)


@dataclass
class Exact:
    """Exact results of a case's points: hi + lo (N, K) float64, ``tolerance`` (N,),
    ``defined`` (N,) bool (False where ``reference.Undefined`` was raised), and
    the exact ``offsets`` s_i = q_i - p of every point."""

    hi: np.ndarray
    lo: np.ndarray
    tolerance: np.ndarray
    defined: np.ndarray
    offsets: list


def exact_results(case: Case, quantity: str, u: float) -> Exact:
    """The exact results and tolerances of ``case`` for ``quantity`` at unit roundoff u.

    Raises ``AssertionError`` when a reference fails its second evaluation.
    """
    width = 4 if quantity == "mean_value" else 2
    hi, lo = np.zeros((len(case.points), width)), np.zeros((len(case.points), width))
    tol, defined = np.full(len(case.points), np.inf), np.zeros(len(case.points), dtype=bool)
    w = homogeneous(case.w)
    exact_offsets = [offsets(p, case.quad) for p in case.points]
    for n, s in enumerate(exact_offsets):
        try:
            if quantity == "mean_value":
                value = mean_value_exact(s, w)
                check_mean_value(s, w, value)
                cond = condition(mean_value_exact, s, w, u, case.far)
            else:
                value = inverse_bilinear_exact(s)
                check_inverse_bilinear(s, value)
                cond = condition(lambda s_, _w, near=value: inverse_bilinear_exact(s_, near), s, None, u, case.far)
        except Undefined:
            continue
        hi[n] = [float(v) for v in value]
        lo[n] = [float(v - h) for v, h in zip(value, hi[n])]
        tol[n], defined[n] = tolerance(cond, u), True
    return Exact(hi, lo, tol, defined, exact_offsets)


def run_case(case: Case, precision: str, methods=METHODS) -> list[Row]:
    """Rows of one case (in float64 inputs) at ``precision`` for ``methods``."""
    u = UNIT_ROUNDOFF[precision]
    rounded = case.rounded(np.dtype(precision))
    quantities = {m.quantity for m in methods if m.quantity == "mean_value" or case.bilinear}
    exact = {q: exact_results(rounded, q, u) for q in sorted(quantities)}
    return [_row(rounded, precision, m, exact[m.quantity], u) for m in methods if m.quantity in exact]


def run(precisions=("float64",), methods=METHODS, cases=None) -> list[Row]:
    """Rows of every case of ``cases`` (default: the catalogue) for every precision and method."""
    cases = catalogue() if cases is None else cases
    return [row for precision in precisions for case in cases for row in run_case(case, precision, methods)]


def _row(case: Case, precision: str, method: Method, exact: Exact, u: float) -> Row:
    ok = exact.defined
    if not ok.any():
        nan = float("nan")
        return Row(case.name, case.group, method.name, method.naive, precision, 0, nan, nan, nan, nan, nan, nan, "skip")
    points = case.points[ok]
    result = method(replace(case, points=points))
    error = properties.error(result, exact.hi[ok], exact.lo[ok], case.far)
    ratio = np.where(np.isnan(error), np.inf, error / exact.tolerance[ok])
    worst = int(np.argmax(ratio))
    s = [v for v, defined in zip(exact.offsets, ok) if defined]
    if method.quantity == "mean_value":
        unity = float(properties.unity(result).max())
        linear = float(np.max(properties.mean_value_linear(result, case.w, s)))
    else:
        unity = float("nan")
        linear = float(np.max(properties.bilinear_linear(result, s, case.quad)))
    lagrange = properties.leak(method.weights(method(replace(case, points=case.quad))), case.quad)
    finite = bool(np.isfinite(result).all())
    defects = np.array([linear, lagrange] + ([unity] if method.quantity == "mean_value" else []))
    passed = finite and float(ratio[worst]) <= 1 and bool((defects <= TOLERANCE_FLOOR * u).all())
    status = "pass" if passed else "fail"
    return Row(
        case.name, case.group, method.name, method.naive, precision, int(ok.sum()),
        float(error[worst]), float(exact.tolerance[ok][worst]), float(ratio[worst]),
        unity, linear, lagrange, status,
    )
