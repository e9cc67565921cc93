"""render.coords: mean value coordinates and inverse bilinear, against closed forms
and a high-precision evaluation of the paper's formulas."""

import mpmath
import numpy as np
import pytest

from render.coords import bilinear_weights, inverse_bilinear, mean_value

CONVEX = np.array([[0.0, 0.0], [2.0, 0.3], [1.6, 1.8], [-0.2, 1.1]])
CONCAVE = np.array([[0.0, 0.0], [2.0, 0.0], [0.6, 0.5], [0.0, 2.0]])  # reflex corner 2
SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def random_points(rng, n, lo=-0.5, hi=2.5):
    return rng.uniform(lo, hi, size=(n, 2))


def bilinear_map(quad, st):
    s, t = st[:, :1], st[:, 1:]
    return (1 - s) * (1 - t) * quad[0] + s * (1 - t) * quad[1] + s * t * quad[2] + (1 - s) * t * quad[3]


def mean_value_reference(p, quad, w=None, digits=50):
    """HT04 eq. 7/8 (with eq. 10/11 for w) at ``digits`` digits, angles by atan2."""
    with mpmath.workdps(digits):
        q = [[mpmath.mpf(float(c)) for c in corner] for corner in quad]
        x, y = mpmath.mpf(float(p[0])), mpmath.mpf(float(p[1]))
        s = [(c[0] - x, c[1] - y) for c in q]
        sign = [1 if w is None or w[i] > 0 else -1 for i in range(4)]
        r = [sign[i] * mpmath.sqrt(s[i][0] ** 2 + s[i][1] ** 2) for i in range(4)]
        t = []
        for i in range(4):
            j = (i + 1) % 4
            A = s[i][0] * s[j][1] - s[i][1] * s[j][0]
            D = s[i][0] * s[j][0] + s[i][1] * s[j][1]
            alpha = mpmath.atan2(A, D)  # the signed angle at p in [p, q_i, q_j]
            if sign[i] != sign[j]:
                alpha += mpmath.pi  # exterior angle (section 3.2)
            t.append(mpmath.tan(alpha / 2))
        mu = [(t[i - 1] + t[i]) / r[i] for i in range(4)]
        if w is not None:
            mu = [mu[i] / mpmath.mpf(float(w[i])) for i in range(4)]
        total = sum(mu)
        return np.array([float(m / total) for m in mu])


@pytest.mark.parametrize("quad", [CONVEX, CONCAVE, SQUARE])
def test_mean_value_partition_of_unity_and_linear_precision(quad):
    rng = np.random.default_rng(1)
    p = random_points(rng, 500)
    lam = mean_value(p, quad)
    assert np.abs(lam.sum(axis=1) - 1).max() < 1e-12
    # Affine functions are reproduced: sum_i lambda_i f(q_i) = f(p).
    affine = np.array([[0.3, -1.2], [2.0, 0.7]])
    offset = np.array([0.25, -3.0])
    assert np.abs(lam @ (quad @ affine + offset) - (p @ affine + offset)).max() < 1e-10


@pytest.mark.parametrize("w", [[1.0, 2.0, 0.5, 3.0], [1.0, 1.5, -0.8, 2.0], [-1.0, 2.0, 1.0, 1.0]])
def test_perspective_mean_value_reproduces_homogeneous_point(w):
    """With w (eq. 10/11) the 3-D point sum lambda'_i V_i projects back to p: in
    homogeneous form sum_i lambda'_i w_i (q_i - p) = 0; weights sum to 1."""
    rng = np.random.default_rng(2)
    w = np.array(w)
    p = random_points(rng, 300, 0.1, 1.4)
    lam = mean_value(p, CONVEX, w)
    assert np.abs(lam.sum(axis=1) - 1).max() < 1e-12
    residual = np.einsum("ni,i,nij->nj", lam, w, CONVEX[None] - p[:, None])
    assert np.abs(residual).max() < 1e-10


def test_perspective_weights_are_plain_weights_over_w():
    rng = np.random.default_rng(3)
    w = np.array([0.7, 1.9, 4.0, 1.2])
    p = random_points(rng, 200, 0.0, 1.5)
    plain = mean_value(p, CONVEX) / w
    expected = plain / plain.sum(axis=1, keepdims=True)
    assert np.abs(mean_value(p, CONVEX, w) - expected).max() < 1e-12


@pytest.mark.parametrize("w", [None, [1.0, 3.0, 0.2, 2.0], [1.0, 1.0, -2.0, 1.0]])
def test_mean_value_lagrange_property_at_corners(w):
    lam = mean_value(CONVEX, CONVEX, w)
    assert np.array_equal(lam, np.eye(4))


def test_mean_value_is_exactly_linear_on_edges():
    u = np.array([0.0, 0.125, 0.5, 0.75, 1.0])
    p = np.stack([u, np.zeros_like(u)], axis=1)  # along edge 0-1 of the unit square
    lam = mean_value(p, SQUARE)
    assert np.array_equal(lam[:, 0], 1 - u)
    assert np.array_equal(lam[:, 1], u)
    assert np.array_equal(lam[:, 2:], np.zeros((5, 2)))
    # With w the edge weights are the perspective-correct linear ones.
    w = np.array([1.0, 3.0, 2.0, 2.0])
    lam_w = mean_value(p, SQUARE, w)
    sigma = (u / w[1]) / ((1 - u) / w[0] + u / w[1])
    assert np.abs(lam_w[:, 1] - sigma).max() < 1e-15
    assert np.array_equal(lam_w[:, 2:], np.zeros((5, 2)))


@pytest.mark.parametrize(
    "quad, w",
    [(CONVEX, None), (CONCAVE, None), (CONVEX, [1.0, 2.5, 0.4, 1.7]), (CONVEX, [1.0, 1.2, -0.9, 1.5])],
)
def test_mean_value_matches_high_precision_eq8(quad, w):
    rng = np.random.default_rng(4)
    p = random_points(rng, 40, -0.3, 2.0)
    lam = mean_value(p, quad, w)
    reference = np.array([mean_value_reference(x, quad, w) for x in p])
    scale = np.maximum(np.abs(reference).max(axis=1, keepdims=True), 1.0)
    assert np.abs((lam - reference) / scale).max() < 1e-11


def test_mean_value_stable_near_edges_and_corners():
    quad = CONVEX
    edge_mid = (quad[1] + quad[2]) / 2
    normal = np.array([quad[2, 1] - quad[1, 1], quad[1, 0] - quad[2, 0]])
    normal /= np.linalg.norm(normal)
    points = [edge_mid + d * normal for d in (1e-8, -1e-8, 1e-12, -1e-12, 1e-15)]
    points += [quad[3] + np.array([1e-13, 2e-13]), quad[0] + np.array([3e-9, 1e-9])]
    p = np.array(points)
    lam = mean_value(p, quad)
    reference = np.array([mean_value_reference(x, quad, digits=60) for x in p])
    assert np.abs(lam - reference).max() < 1e-14


@pytest.mark.parametrize("far", [[1e6, 3e5], [-2e7, 1e7], [3e3, -1e4]])
def test_mean_value_far_points_within_their_condition(far):
    """Far out (distance R, quad size L) the inputs q_i - p carry a relative
    rounding u, which moves the result by about (R / L) u relative: the edge
    form of A_i stays within a small multiple of that."""
    p = np.array([far])
    lam = mean_value(p, CONVEX)
    reference = mean_value_reference(p[0], CONVEX, digits=60)
    condition = np.linalg.norm(far) / 2.0 * np.finfo(float).eps
    assert np.abs(lam[0] - reference).max() / np.abs(reference).max() < 16 * condition


def test_mean_value_tiny_and_offset_quads_are_scale_free():
    rng = np.random.default_rng(5)
    p = random_points(rng, 100, 0.2, 1.2)
    lam = mean_value(p, CONVEX)
    for scale, offset in [(1e-9, 0.0), (1e9, 0.0), (1.0, 1e8)]:
        moved = mean_value(p * scale + offset, CONVEX * scale + offset)
        assert np.abs(moved - lam).max() < 1e-6 if offset else np.abs(moved - lam).max() < 1e-12


def test_mean_value_degenerate_quads_give_finite_documented_values():
    triangle_as_quad = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 1.0]])  # repeated corner
    p = np.array([[0.2, 0.3], [0.5, 0.5], [0.0, 1.0]])
    lam = mean_value(p, triangle_as_quad)
    barycentric = np.stack([1 - p.sum(axis=1), p[:, 0], p[:, 1]], axis=1)
    assert np.abs(lam[:, :2] - barycentric[:, :2]).max() < 1e-14
    assert np.abs(lam[:, 2] + lam[:, 3] - barycentric[:, 2]).max() < 1e-14

    collinear = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]])  # zero area
    p = np.array([[4.0, 0.0], [0.5, 0.0], [1.5, 1.0]])
    lam = mean_value(p, collinear)
    assert np.all(np.isfinite(lam))
    assert np.array_equal(lam[0], [0.0, 0.0, 0.0, 1.0])  # undefined: nearest corner
    assert np.array_equal(lam[1], [0.5, 0.5, 0.0, 0.0])  # on edge 0

    bowtie = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
    lam = mean_value(np.array([[0.5, 0.5], [0.9, 0.5], [0.1, 0.5]]), bowtie)
    assert np.all(np.isfinite(lam))
    assert np.abs(lam.sum(axis=1) - 1).max() < 1e-12


def test_mean_value_rejects_w_zero():
    with pytest.raises(ValueError, match="nonzero"):
        mean_value([[0.5, 0.5]], SQUARE, [1.0, 0.0, 1.0, 1.0])


@pytest.mark.parametrize(
    "quad",
    [
        CONVEX,
        np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 1.0], [0.0, 1.0]]),  # exact parallelogram
        np.array([[0.0, 0.0], [3.0, 0.5], [4.0, 2.5], [1.0, 2.0]]),  # exact, slanted
        np.array([[0.0, 0.0], [3.0, 0.5], [4.0, 2.5 + 1e-9], [1.0, 2.0]]),  # near-parallelogram
        np.array([[0.0, 0.0], [3.0, 0.5], [4.0, 2.5 + 1e-4], [1.0, 2.0]]),
        np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 1.0], [1.0, 1.0]]),  # pole: edge 2-3 collapsed
    ],
)
def test_inverse_bilinear_inverts_the_bilinear_map(quad):
    rng = np.random.default_rng(6)
    st = rng.uniform(0, 1, size=(400, 2))
    st = np.vstack([st, [[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 1 - 1e-9], [0.3, 0.999999]]])
    recovered = inverse_bilinear(bilinear_map(quad, st), quad)
    collapsed = np.allclose(quad[2], quad[3])
    if collapsed:  # on the collapsed edge every s is the same point: compare points
        assert np.abs(bilinear_map(quad, recovered) - bilinear_map(quad, st)).max() < 1e-12
        away = st[:, 1] < 1 - 1e-6
        assert np.abs(recovered[away] - st[away]).max() < 1e-9
    else:
        assert np.abs(recovered - st).max() < 1e-9


def test_inverse_bilinear_per_point_quads_and_weights():
    rng = np.random.default_rng(7)
    quads = CONVEX[None] + rng.normal(scale=0.05, size=(50, 4, 2))
    st = rng.uniform(0, 1, size=(50, 2))
    points = np.einsum("nk,nkj->nj", bilinear_weights(st[:, 0], st[:, 1]).T, quads)
    assert np.abs(inverse_bilinear(points, quads) - st).max() < 1e-10


def test_inverse_bilinear_outside_and_degenerate_is_finite():
    far = np.array([[50.0, -30.0], [1e9, 1e9], [-3.0, 0.5]])
    for quad in (CONVEX, CONCAVE, np.zeros((4, 2)), np.array([[0.0, 0], [1, 1], [1, 0], [0, 1]])):
        assert np.all(np.isfinite(inverse_bilinear(far, quad)))
