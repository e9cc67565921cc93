"""The visible reading of a quad's uv crease: how much the split changes what the texture shows.

design.md, "The visible reading": for a quad with planar corners p_0..p_3 and uv
a_0..a_3, its bilinear patch P(s, t) = (1-s)(1-t) p_0 + s(1-t) p_1 + s t p_2 +
(1-s) t p_3 carries the exact uv (the same weights on a_k), and the split carries
the uv of the triangle of its diagonal that holds P (barycentric weights of P in
that triangle on its corners' a_k). With T the texture filtered bilinearly at its
base level,

    C = max over (s, t) of max over channels |T(uv_split(P)) - T(uv_exact(P))|

in 1/255 steps, or of the angle between the two decoded normals (normal maps),
in degrees. C is evaluated in three passes, all vectorized over quads:

1. bound: both uv lie in the convex hull of the corners' uv (convex quads), so no
   channel changes by more than its range over the texels that hull reaches, read
   from a min/max pyramid (:class:`~affinity.textures.filtering.RangePyramid`); a
   quad whose range is under one step (or under the warning's, if lower) is given
   that range as an upper bound (``AT_MOST``);
2. coarse: an 8 x 8 grid of (s, t); a quad at or above the error threshold there is
   done, its value a lower bound (``AT_LEAST``);
3. fine: a grid of about two samples per texel of the quad's uv extent (16 to 256 per
   side), then a 9 x 9 grid over the cells around the worst sample. A sampled maximum
   is a lower bound of C: one at or above the error threshold says ``AT_LEAST``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .filtering import RangePyramid, sample_bilinear, texel_coordinates

#: ``bound`` codes of a value: exact to the sampling, known to be at least, known to be at most.
EXACT, AT_LEAST, AT_MOST = 0, 1, 2
BOUND_NAMES = {AT_LEAST: "at least", AT_MOST: "at most"}
#: Diagonal codes per quad: the split along 0-2, along 1-3, or the worse of both.
DIAGONAL_02, DIAGONAL_13, BOTH_DIAGONALS = 0, 1, 2
COARSE = 8
FINE_MIN, FINE_MAX = 16, 256
#: Fine samples per texel of the quad's uv extent, per side.
SAMPLES_PER_TEXEL = 2.0
#: Sample points evaluated together (each costs two bilinear lookups).
POINTS_PER_CHUNK = 1 << 19


@dataclass(frozen=True)
class VisibleLimits:
    """The ``visible-*`` settings: ``error`` and ``warning`` in 1/255 steps (degrees for normal maps),
    ``min_shift`` in texels."""

    error: float = 8.0
    warning: float = 2.0
    min_shift: float = 1.0

    def levels(self, values: np.ndarray, shifts: np.ndarray) -> np.ndarray:
        """(n,) str: error where C >= error and the shift >= min_shift; warning where C >= error below
        that shift or warning <= C < error; info where C < warning (design.md)."""
        return np.where(values >= self.error, np.where(shifts >= self.min_shift, "error", "warning"),
                        np.where(values >= self.warning, "warning", "info"))


def bilinear_weights(st: np.ndarray) -> np.ndarray:
    """(M, 4) float64 weights of the corners at parameters ``st`` (M, 2) of the bilinear patch."""
    s, t = st[:, 0], st[:, 1]
    return np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t], axis=1)


def split_weights(xy: np.ndarray, points: np.ndarray, diagonal: int) -> np.ndarray:
    """(Q, M, 4) float64 corner weights of the split along ``diagonal`` (``DIAGONAL_02`` or ``DIAGONAL_13``) at
    ``points`` (Q, M, 2), quads ``xy`` (Q, 4, 2): the barycentric coordinates of each point in the triangle of
    the diagonal i-k that holds it, (i, j, k) or (i, k, m). A point both or neither hold (a concave quad,
    whose triangles overlap outside it) takes the triangle it lies deeper in (the larger smallest weight), as
    a renderer shows the triangle that covers the point; a degenerate triangle gives zero weights."""
    i, j, k, m = (0, 1, 2, 3) if diagonal == DIAGONAL_02 else (1, 2, 3, 0)
    first, first_ok = _barycentric(xy[:, [i, j, k]], points)
    second, second_ok = _barycentric(xy[:, [i, k, m]], points)
    in_first = np.where(first_ok & second_ok, first.min(axis=-1) >= second.min(axis=-1), first_ok)
    weights = np.zeros((*points.shape[:2], 4))
    weights[..., [i, j, k]] = np.where(in_first[..., None], first, 0.0)
    weights[..., [i, k, m]] += np.where(in_first[..., None], 0.0, second)
    return weights


def _barycentric(triangles: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(Q, M, 3) float64 barycentric coordinates of ``points`` (Q, M, 2) in ``triangles`` (Q, 3, 2), and
    (Q, 1) bool which triangles have an area (the others' coordinates are 0)."""
    a, b, c = triangles[:, None, 0], triangles[:, None, 1], triangles[:, None, 2]

    def cross(u, v):
        return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

    doubled_area = cross(b - a, c - a)  # (Q, 1)
    usable = doubled_area != 0
    safe = np.where(usable, doubled_area, 1.0)
    w_b = cross(points - a, c - a) / safe
    w_c = cross(b - a, points - a) / safe
    weights = np.stack([1.0 - w_b - w_c, w_b, w_c], axis=-1)
    return np.where(usable[..., None], weights, 0.0), usable


def texture_difference(pixels: np.ndarray, uv_a: np.ndarray, uv_b: np.ndarray, normal_map: bool) -> np.ndarray:
    """(N,) float64: the largest channel difference of the texture ``pixels`` (H, W, C) uint8 between
    uv ``uv_a`` and ``uv_b`` (N, 2), in 1/255 steps; for a normal map the angle between the decoded
    normals (2 c / 255 - 1 per channel, first three channels), in degrees."""
    a, b = sample_bilinear(pixels, uv_a), sample_bilinear(pixels, uv_b)
    if not normal_map:
        return np.abs(a - b).max(axis=1).astype(np.float64)
    n_a, n_b = a[:, :3].astype(np.float64) / 127.5 - 1.0, b[:, :3].astype(np.float64) / 127.5 - 1.0
    sine = np.linalg.norm(np.cross(n_a, n_b), axis=1)
    return np.degrees(np.arctan2(sine, np.einsum("ij,ij->i", n_a, n_b)))


def grid(n: int) -> np.ndarray:
    """((n + 1)^2, 2) float64 (s, t) on a regular grid over [0, 1]^2."""
    ticks = np.linspace(0.0, 1.0, n + 1)
    s, t = np.meshgrid(ticks, ticks, indexing="ij")
    return np.stack([s.ravel(), t.ravel()], axis=1)


def crease_difference(pixels: np.ndarray, xy: np.ndarray, uv: np.ndarray, diagonals: np.ndarray, st: np.ndarray,
                      normal_map: bool) -> np.ndarray:
    """(Q, M) float64: the texture difference between the split's and the exact uv at parameters ``st``
    (M, 2) or (Q, M, 2) of quads ``xy`` (Q, 4, 2) with texture uv ``uv`` (Q, 4, 2), the worse of the
    diagonals ``diagonals`` (Q,) int names."""
    weights = bilinear_weights(st.reshape(-1, 2)).reshape(*st.shape[:-1], 4)
    if weights.ndim == 2:
        weights = np.broadcast_to(weights, (len(xy), *weights.shape))
    points = np.einsum("qmk,qkd->qmd", weights, xy)
    exact = np.einsum("qmk,qkd->qmd", weights, uv)
    worst = np.zeros(points.shape[:2])
    for diagonal in (DIAGONAL_02, DIAGONAL_13):
        rows = np.flatnonzero((diagonals == diagonal) | (diagonals == BOTH_DIAGONALS))
        if not len(rows):
            continue
        split = np.einsum("qmk,qkd->qmd", split_weights(xy[rows], points[rows], diagonal), uv[rows])
        difference = texture_difference(pixels, split.reshape(-1, 2), exact[rows].reshape(-1, 2), normal_map)
        difference = difference.reshape(len(rows), -1)
        worst[rows] = np.maximum(worst[rows], difference)
    return worst


def _chunks(n_quads: int, points_per_quad: int):
    """Slices of quads evaluated together, about :data:`POINTS_PER_CHUNK` sample points each."""
    step = max(1, POINTS_PER_CHUNK // max(points_per_quad, 1))
    return (slice(start, start + step) for start in range(0, n_quads, step))


def hull_range(pyramid: RangePyramid, texel_xy: np.ndarray, convex: np.ndarray) -> np.ndarray:
    """(Q,) float64: the largest channel range over the texels bilinear filtering reaches inside the
    uv box of each quad (``texel_xy`` (Q, 4, 2) its corners in texel coordinates); NaN where no bound
    holds: a quad that is not ``convex`` (its split leaves the hull) or whose box wraps around the texture."""
    height, width = pyramid.shape[:2]
    x0, y0 = np.floor(texel_xy.min(axis=1)).T
    x1, y1 = np.floor(texel_xy.max(axis=1)).T + 1
    inside = convex & (x0 >= 0) & (y0 >= 0) & (x1 <= width - 1) & (y1 <= height - 1)
    result = np.full(len(texel_xy), np.nan)
    rows = np.flatnonzero(inside)
    if len(rows):
        result[rows] = pyramid.channel_range(*(a[rows].astype(np.int64) for a in (x0, x1, y0, y1)))
    return result


def is_convex(xy: np.ndarray) -> np.ndarray:
    """(Q,) bool: the planar quads ``xy`` (Q, 4, 2) turn the same way at every corner (zero turns allowed)."""
    edges = np.roll(xy, -1, axis=1) - xy
    turns = edges[:, :, 0] * np.roll(edges, -1, axis=1)[:, :, 1] - edges[:, :, 1] * np.roll(edges, -1, axis=1)[:, :, 0]
    return (turns >= 0).all(axis=1) | (turns <= 0).all(axis=1)


def visible_values(pixels: np.ndarray, xy: np.ndarray, uv: np.ndarray, diagonals: np.ndarray, normal_map: bool,
                   limits: VisibleLimits, pyramid: RangePyramid | None = None) -> tuple[np.ndarray, np.ndarray]:
    """C for quads through one texture.

    Parameters
    ----------
    pixels : (H, W, C) uint8, the decoded texture
    xy : (Q, 4, 2) float64, the quads' corners in their own planes
    uv : (Q, 4, 2) float64, where the corners read the texture (after any ``-s``/``-o``)
    diagonals : (Q,) int, ``DIAGONAL_02``, ``DIAGONAL_13`` or ``BOTH_DIAGONALS``
    normal_map : the texture holds tangent-space normals (C in degrees)
    limits : the error threshold ends refinement
    pyramid : the texture's min/max pyramid (built here when None)

    Returns
    -------
    values : (Q,) float64, C in 1/255 steps or degrees
    bounds : (Q,) int8, ``EXACT``, ``AT_LEAST`` or ``AT_MOST``
    """
    n = len(xy)
    values, bounds = np.zeros(n), np.full(n, EXACT, dtype=np.int8)
    if n == 0:
        return values, bounds
    height, width = pixels.shape[:2]
    texel_xy = texel_coordinates(uv, width, height)
    pyramid = pyramid or RangePyramid(pixels)
    spread = hull_range(pyramid, texel_xy, is_convex(xy))
    negligible = spread == 0 if normal_map else spread < min(1.0, limits.warning)  # NaN: no bound
    values[negligible], bounds[negligible] = spread[negligible], AT_MOST
    todo = np.flatnonzero(~negligible)

    coarse = grid(COARSE)
    for part in _chunks(len(todo), len(coarse)):
        rows = todo[part]
        values[rows] = crease_difference(pixels, xy[rows], uv[rows], diagonals[rows], coarse, normal_map).max(axis=1)
    done = values[todo] >= limits.error
    bounds[todo[done]] = AT_LEAST
    todo = todo[~done]

    extent = np.ptp(texel_xy[todo], axis=1).max(axis=1)
    sides = np.clip(2 ** np.ceil(np.log2(np.maximum(extent * SAMPLES_PER_TEXEL, 1))), FINE_MIN, FINE_MAX)
    for side in np.unique(sides).astype(int).tolist():  # one size bucket at a time (at most 5), not per quad
        bucket = todo[sides == side]
        fine = grid(side)
        for part in _chunks(len(bucket), len(fine)):
            rows = bucket[part]
            difference = crease_difference(pixels, xy[rows], uv[rows], diagonals[rows], fine, normal_map)
            worst = difference.argmax(axis=1)
            values[rows] = np.maximum(values[rows], difference[np.arange(len(rows)), worst])
            local = fine[worst][:, None, :] + (grid(8) - 0.5)[None] * (2.0 / side)  # the cells around the worst
            local = np.clip(local, 0.0, 1.0)
            refined = crease_difference(pixels, xy[rows], uv[rows], diagonals[rows], local, normal_map)
            values[rows] = np.maximum(values[rows], refined.max(axis=1))
    bounds[todo[values[todo] >= limits.error]] = AT_LEAST
    return values, bounds
