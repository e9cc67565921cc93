"""Interpolation planes of clip-space triangles, in pixel coordinates.

For a triangle with clip-space corners P_k = (x_k, y_k, w_k) (z aside) and
C_k = P_{k+1} x P_{k+2}, a pixel centre p = (px, py, 1) in NDC has the
homogeneous barycentrics c_k = p . C_k / det, det = P_0 . C_0 (Olano & Greer):
p = sum_k c_k P_k, so sum_k c_k w_k = 1 and the 3-D point seen at p is the
combination of the corners with weights c_k / sum_j c_j. Hence, with every
quantity affine in p:

- perspective-correct attribute a = (sum_k c_k a_k) / (sum_k c_k), i.e. the
  interpolated a/w over the interpolated 1/w;
- NDC depth z = sum_k c_k z_k (the clip z of the corners).

None of this divides by a corner's w, so it holds for corners behind the eye
or on the eye plane; det is 0 exactly for triangles seen edge-on or
degenerate. The planes are stored for pixel (row r, column c) as
value = v0 + vc * c + vr * r.
"""

from __future__ import annotations

import numpy as np


def triangle_planes(tri, values, width, height):
    """Homogeneous determinant and interpolation planes of triangles.

    Parameters
    ----------
    tri : (4, 3, T) float64
        Clip-space corners, component-major (x, y, z, w; corner; triangle).
    values : (M, 3, T) float64
        Per-corner values to interpolate as sum_k c_k v_k (pass 1 for the
        denominator of perspective-correct attributes, z for depth).
    width, height : int
        Image size, for the NDC -> pixel change of coordinates.

    Returns
    -------
    det : (T,) float64
        det(P_0, P_1, P_2) over (x, y, w); > 0 for triangles counter-clockwise
        in NDC (front-facing), 0 for degenerate or edge-on ones.
    planes : (3, M, T) float64
        v0, vc and vr of every value; not finite where det is 0.
    """
    x, y, w = tri[0], tri[1], tri[3]
    nxt, far = [1, 2, 0], [2, 0, 1]
    x1, y1, w1, x2, y2, w2 = x[nxt], y[nxt], w[nxt], x[far], y[far], w[far]
    C = (y1 * w2 - w1 * y2, w1 * x2 - x1 * w2, x1 * y2 - y1 * x2)  # C_k, (3, T) per component
    det = x[0] * C[0][0] + y[0] * C[1][0] + w[0] * C[2][0]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        inv = 1.0 / det
        # sum_k v_k C_k / det per component, (M, T) each
        nx, ny, n1 = (sum(values[:, k] * (c[k] * inv) for k in range(3)) for c in C)
        planes = np.stack(
            [
                nx * (1.0 / width - 1.0) + ny * (1.0 - 1.0 / height) + n1,
                nx * (2.0 / width),
                ny * (-2.0 / height),
            ]
        )
    return det, planes


def evaluate(planes, col, row) -> np.ndarray:
    """Values of planes (3, M, N) at pixels col, row (N,) -> (M, N)."""
    return planes[0] + planes[1] * col + planes[2] * row
