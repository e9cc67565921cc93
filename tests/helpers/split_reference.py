"""An independent reference for the split's error: sampled, never the closed form.

The split along a diagonal is evaluated by 3-D point-in-triangle barycentrics at
bilinear positions P(s, t) on a grid of the quad's parameters, against the
bilinear blend of the corner values at (s, t). The supremum is found by zooming
the grid in on the largest sample. Nothing here imports ``affinity.measures``.
"""

from __future__ import annotations

import numpy as np

TRIANGLES = {"02": ((0, 1, 2), (0, 2, 3)), "13": ((1, 2, 3), (1, 3, 0))}


def bilinear(values: np.ndarray, s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(4, K) corner values blended at parameters (N,) -> (N, K)."""
    w = np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t], axis=1)
    return w @ values


def triangle_barycentrics(points: np.ndarray, a, b, c) -> np.ndarray:
    """(N, 3) barycentrics of 3-D points in triangle (a, b, c), from cross products
    with the triangle's normal n = (b - a) x (c - a); NaN for a triangle of no area.

    The cross products keep a sliver's area to a relative error of about
    eps |b - a| |c - a| / |n|; the Gram determinant d00 d11 - d01^2 (Ericson 3.4)
    squares that cancellation and loses a 1e-9 sliver altogether.
    """
    v0, v1, v2 = b - a, c - a, points - a
    normal = np.cross(v0, v1)
    area2 = normal @ normal
    if not area2 > 1e-30 * (v0 @ v0) * (v1 @ v1):
        return np.full((len(points), 3), np.nan)
    v = np.cross(v2, v1) @ normal / area2
    w = np.cross(v0, v2) @ normal / area2
    return np.stack([1 - v - w, v, w], axis=1)


def split_minus_bilinear(corners, values, diagonal, s, t) -> np.ndarray:
    """(N,) |split - bilinear| at parameters (N,): the point goes to the triangle of the
    split that contains it best (largest smallest barycentric)."""
    points = bilinear(corners, s, t)
    exact = bilinear(values, s, t)
    best, split = np.full(len(s), -np.inf), np.zeros_like(exact)
    for triangle in TRIANGLES[diagonal]:
        b = triangle_barycentrics(points, *corners[list(triangle)])
        inside = np.nan_to_num(b.min(axis=1), nan=-np.inf)
        better = inside > best
        split[better] = (b @ values[list(triangle)])[better]
        best = np.maximum(best, inside)
    return np.linalg.norm(split - exact, axis=1)


def sampled_sup(corners, values, diagonal="02", n=81, zooms=16) -> float:
    """The largest |split - bilinear| over the unit parameter square, by zooming a
    grid of n x n samples in on its best sample. ``diagonal`` "both" takes the worse."""
    if diagonal == "both":
        return max(sampled_sup(corners, values, d, n, zooms) for d in TRIANGLES)
    corners, values = np.asarray(corners, float), np.asarray(values, float).reshape(4, -1)
    lo, hi = np.zeros(2), np.ones(2)
    best = 0.0
    for _ in range(zooms):
        s, t = np.meshgrid(np.linspace(lo[0], hi[0], n), np.linspace(lo[1], hi[1], n), indexing="ij")
        error = split_minus_bilinear(corners, values, diagonal, s.ravel(), t.ravel())
        k = int(np.argmax(error))
        best = max(best, float(error[k]))
        centre, half = np.array([s.ravel()[k], t.ravel()[k]]), 3 * (hi - lo) / (n - 1)
        lo, hi = np.clip(centre - half, 0, 1), np.clip(centre + half, 0, 1)
    return best


def random_plane_frame(rng) -> np.ndarray:
    """(3, 3) rotation whose first two rows span a random plane."""
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q.T


def random_convex_quad(rng) -> np.ndarray:
    """(4, 2) strictly convex quad, counter-clockwise: four sorted angles on an ellipse,
    scaled at random."""
    while True:
        angles = np.sort(rng.uniform(0, 2 * np.pi, 4))
        gaps = np.diff(np.append(angles, angles[0] + 2 * np.pi))
        if gaps.min() > 0.15 and gaps.max() < np.pi - 0.15:
            radius = rng.uniform(0.5, 1.5, 4)
            xy = np.column_stack([np.cos(angles), np.sin(angles)]) * radius[:, None] * rng.uniform(0.3, 3, 2)
            edges = np.roll(xy, -1, axis=0) - xy
            turns = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
            if turns.min() > 0.05 * np.abs(turns).max():
                return xy
