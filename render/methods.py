"""The interpolation methods, and the corner weights of those that need them.

- ``split``: the two triangles (0, 1, 2) and (0, 2, 3), with perspective-correct
  attributes (a/w over 1/w) from the triangle's interpolation planes
  (``render.planes``); no per-pixel weights.
- ``mvc``: Hormann & Tarini's mean value coordinates with the perspective
  terms of eq. 10 and 11, computed by ``coords.mean_value_terms`` and
  ``coords.mean_value_from_terms`` on the homogeneous offsets
  s~_i = X_i - p W_i of the pixel centre p (NDC) from the clip-space corners
  (X_i, Y_i, W_i) -- that is w_i (q_i - p) for a corner in front of the eye,
  finite for a corner on the eye plane (W_i = 0) and signed for one behind
  it. On edge i it gives exactly the perspective-correct linear weights
  |s~_{i+1}| : |s~_i|, the same as split, so mvc and split quads agree along
  shared edges.
- ``bilinear``: the inverse bilinear map of the *screen* quad (Bloomenthal
  section 3.3), deliberately not perspective-correct. A quad with a corner on
  or behind the eye plane has no screen quad; its pixels use mvc weights.
- ``projective``: the two triangles of the split, interpolating (q a, q)
  linearly in screen space and dividing, with per-corner q from the
  intersection of the screen quad's diagonals (``projective_corner_weights``).
  This reproduces a parallelogram of attributes mapped projectively onto the
  screen quad (a planar parallelogram in perspective), not every affine field
  on a trapezoid. It is the split's plane machinery with the per-corner
  weights rho_i = w_i q_i in place of 1.

- ``exact``: the float64 reference. The pixel's eye ray meets the quad taken
  as a bilinear patch in 3-D (``render.patch``, solved in homogeneous clip
  space, which has the same patch parameters (s, t) as world space), and the
  corner attributes are weighted bilinearly in (s, t). For a planar quad that
  is perspective-correct inverse bilinear interpolation in the quad's plane;
  for a nonplanar one it is the surface a modelling tool means. Where the ray
  misses the patch (pixel centres that fixed-point coverage admits a hair
  outside the outline, and quads with a corner at w <= 0) the parameters are
  clamped into the unit square (``ray_patch_parameters``).

A new weight method is one more entry in ``WEIGHTS`` (and in ``QUAD_COVERAGE``
if it fills the quad rather than its two triangles). Weight methods receive the
quads' clip-space corners (4, 4, N): x, y, z, w; corner; pixel.
"""

from __future__ import annotations

import numpy as np

from render.coords import (
    NEXT,
    bilinear_parameters,
    bilinear_weights,
    mean_value_from_terms,
    mean_value_terms,
)
from render.patch import ray_patch_parameters


def mvc_weights(corners, px, py) -> np.ndarray:
    """Perspective mean value weights (HT04 eq. 8, 10, 11) of pixels in their quads.

    corners : (4, 4, N) float64 clip x, y, z, w; px, py : (N,). Returns (4, N) float64.
    """
    X, Y, _, W = corners
    sx, sy = X - px * W, Y - py * W  # s~_i = X_i - p W_i
    dW = W[NEXT] - W
    # Homogeneous edge vectors s~_{i+1} - s~_i, formed from the corners.
    ex = (X[NEXT] - X) - px * dW
    ey = (Y[NEXT] - Y) - py * dW
    return mean_value_from_terms(*mean_value_terms(sx, sy, ex, ey))


def bilinear_screen_weights(corners, px, py) -> np.ndarray:
    """Weights of the inverse bilinear map of the screen quad (not perspective-correct).

    corners : (4, 4, N) float64 clip x, y, z, w; px, py : (N,). Returns (4, N)
    float64. Pixels of quads with a corner at W <= 0 get ``mvc_weights`` instead.
    """
    X, Y, _, W = corners
    projectable = (W > 0).all(axis=0)
    if projectable.all():
        return bilinear_weights(*bilinear_parameters(px, py, X / W, Y / W))
    lam = mvc_weights(corners, px, py)
    ok = np.flatnonzero(projectable)
    lam[:, ok] = bilinear_screen_weights(np.take(corners, ok, axis=2), px[ok], py[ok])
    return lam


def exact_weights(corners, px, py) -> np.ndarray:
    """Bilinear weights at the nearest ray / patch hit (``render.patch``).

    corners : (4, 4, N) float64 clip x, y, z, w; px, py : (N,). Returns (4, N) float64.
    """
    s, t, _ = ray_patch_parameters(corners, px, py)
    return bilinear_weights(s, t)


def projective_corner_weights(clip) -> np.ndarray:
    """Per-corner weights rho_i = w_i q_i (Q, 4) of the projective method.

    clip : (Q, 4, 4) clip-space corners. With c the intersection of the screen
    diagonals, c = q0 + s (q2 - q0) = q1 + t (q3 - q1), and d_i = |q_i - c|,
    q_i = (d_i + d_{i+2}) / d_{i+2}, i.e. q = (1 / (1 - s), 1 / (1 - t), 1 / s,
    1 / t). Interpolating rho a and rho with the homogeneous barycentrics c_k of
    a split triangle (for which the screen-space barycentrics are c_k w_k) is
    interpolating q a and q linearly on the screen. Quads that are not
    strictly convex on screen, or have a corner at w <= 0, have no such q:
    they get rho = 1, the plain perspective-correct split. So does a quad with
    a repeated corner, or one repeated to within rounding (a pole quad): its
    diagonals meet at that corner, s or t is 0 or 1 up to rounding, and
    projective there is defined as the split of its one non-degenerate
    triangle. The guard is relative: s and t must keep a margin from 0 and 1 of
    16 eps times the condition of their quotients, (|g| |f| + |g| |e|) / |e x f|
    with g = q1 - q0 and e, f the diagonals, plus 16 eps.
    """
    W = clip[..., 3]
    projectable = (W > 0).all(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        x, y = clip[..., 0] / W, clip[..., 1] / W
        e = (x[:, 2] - x[:, 0], y[:, 2] - y[:, 0])
        f = (x[:, 3] - x[:, 1], y[:, 3] - y[:, 1])
        g = (x[:, 1] - x[:, 0], y[:, 1] - y[:, 0])
        ef = e[0] * f[1] - e[1] * f[0]
        s = (g[0] * f[1] - g[1] * f[0]) / ef
        t = (g[0] * e[1] - g[1] * e[0]) / ef
        rho = W * np.stack([1 / (1 - s), 1 / (1 - t), 1 / s, 1 / t], axis=1)
        length_g = np.hypot(*g)
        margin = 16 * np.finfo(np.float64).eps * (1 + length_g * (np.hypot(*e) + np.hypot(*f)) / np.abs(ef))
    convex = projectable & (s > margin) & (s < 1 - margin) & (t > margin) & (t < 1 - margin)
    return np.where(convex[:, None], rho, 1.0)


METHODS = ("split", "mvc", "bilinear", "projective", "exact")
PLANE_METHODS = frozenset({"split", "projective"})
WEIGHTS = {"mvc": mvc_weights, "bilinear": bilinear_screen_weights, "exact": exact_weights}
QUAD_COVERAGE = frozenset({"mvc", "bilinear", "exact"})
