"""The naive forms of issue 11 on the catalogue: each is a faithful implementation
(it passes the generic case) and each fails stiff cases that the project's forms
pass, so these tests can fail if the project's forms regress to the naive ones."""

import math

import numpy as np
import pytest

from affinity.stability import naive
from affinity.stability.cases import catalogue
from affinity.stability.run import METHODS, run
from render.coords import inverse_bilinear, mean_value

#: Where each naive form's error exceeds the condition tolerance, by the cause issue 11 names.
BREAKS = {
    "naive_acos": {  # acos loses half the digits near pi (edges) and near 0 (needles, far points)
        "edge-outside-1e-10", "edge-inside-1e-12", "needle-1e5", "needle-1e8", "far-1e4",
        "edges-exact",  # sign(A) = 0 on the edge
    },
    "naive_guarded": {  # abs(A) < 1e-6 ? 0: scale-dependent, and 0 where the limit is infinite
        "scale-1e-4", "scale-1e-9", "edges-exact", "corner-near-1e-8", "far-1e6",
    },
    "naive_cross_area": {"far-1e4", "far-1e6"},  # s_i x s_{i+1} of two long, nearly parallel vectors
    "naive_textbook": {  # the quadratic formula as the leading coefficient vanishes
        "parallelogram-exact", "parallelogram-rectangle", "parallelogram-defect-1e-9", "parallelogram-defect-1e-12",
    },
    "naive_thresholded": {  # the absolute 1e-5 threshold is right at one scale only
        "scale-1e-4", "scale-1e-9", "parallelogram-defect-1e-6",
    },
}


@pytest.fixture(scope="module")
def rows():
    return {(r.case, r.method): r for r in run(("float64",))}


def beyond(row):
    """The error exceeds the tolerance, or is not finite."""
    return not row.ratio <= 1


@pytest.mark.parametrize("method", sorted(BREAKS))
def test_naive_form_is_faithful_on_the_generic_case(rows, method):
    assert rows["inside", method].ratio <= 1


@pytest.mark.parametrize("method", sorted(BREAKS))
def test_naive_form_fails_cases_the_project_passes(rows, method):
    project = next(m.name for m in METHODS if not m.naive and m.quantity == _quantity(method))
    for case in BREAKS[method]:
        assert beyond(rows[case, method]), (method, case, rows[case, method].ratio)
        assert rows[case, project].status == "pass", (project, case)


def _quantity(method):
    return next(m.quantity for m in METHODS if m.name == method)


def test_every_naive_form_in_the_run_is_covered():
    assert {m.name for m in METHODS if m.naive} == set(BREAKS)


def test_the_failures_the_issue_describes():
    cases = {c.name: c for c in catalogue()}
    # Bloomenthal's guard gives NaN for a quad of size 1e-4.
    small = cases["scale-1e-4"]
    assert np.isnan(naive.mean_value_guarded(small.points, small.quad)).all()
    # The textbook quadratic divides by zero at an exact parallelogram.
    exact = cases["parallelogram-exact"]
    assert not np.isfinite(naive.inverse_bilinear_textbook(exact.points, exact.quad)).all()
    # ... and loses every digit near one: defect 1e-12 leaves about 4 correct digits at some point.
    near = cases["parallelogram-defect-1e-12"]
    error = np.abs(naive.inverse_bilinear_textbook(near.points, near.quad) - inverse_bilinear(near.points, near.quad))
    assert error.max() > 1e-4
    # The paper's A_i for a point 1e6 quad sizes away: error ~ (R / L)^2 u, relative.
    far = cases["far-1e6"]
    good, bad = mean_value(far.points, far.quad), naive.mean_value_cross_area(far.points, far.quad)
    assert np.abs(bad - good).max() / np.abs(good).max() > 1e-7
    assert math.isfinite(float(np.abs(bad).max()))
