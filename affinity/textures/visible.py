"""The visible reading of a quad's uv crease: how much the split changes what the texture shows.

design.md, "The visible reading": for a quad with planar corners p_0..p_3 and uv
a_0..a_3, its bilinear patch P(s, t) = (1-s)(1-t) p_0 + s(1-t) p_1 + s t p_2 +
(1-s) t p_3 carries the exact uv (the same weights on a_k), and the split carries
the uv of the triangle of its diagonal that holds P (barycentric weights of P in
that triangle on its corners' a_k). With T the texture filtered bilinearly at its
base level,

    C = max over (s, t) of max over channels |T(uv_split(P)) - T(uv_exact(P))|

in 1/255 steps, or of the angle between the two decoded normals (normal maps),
in degrees. Both uv are bilinear in (s, t) (the split's per triangle, see
:func:`corner_barycentrics`), so every sample is a small matrix product. C is
found by branch and bound, every pass vectorized over quads:

1. bound: over the quad both uv lie in the box of the exact uv's and the two
   triangles' uv at its corners (:func:`cell_boxes`), so no channel changes by
   more than its range over the texels that box reaches, nor by more than the
   texture's steepest step there times the split's largest shift (:func:`crease_bound`,
   read from min/max pyramids, :class:`~affinity.textures.filtering.RangePyramid`); a
   quad bounded under one step (or under the warning's, if lower) is given that bound
   as its value (``AT_MOST``);
2. cells: the (s, t) square is cut into g x g cells about :data:`CELL_TEXELS` texels
   of uv wide; their corners are the first samples, and a quad at or above the error
   threshold there is done (``AT_LEAST``: refinement stops). A cell whose bound (the
   same, over the cell) is no more than :data:`TOLERANCE` over the quad's best so far
   is left out;
3. samples: the other cells at about two samples per texel of their uv extent, then a
   9 x 9 grid around the worst sample. A sampled maximum is a lower bound of C: one
   at or above the error threshold says ``AT_LEAST``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .filtering import PackedTexture, RangePyramid, texel_coordinates

#: ``bound`` codes of a value: exact to the sampling, known to be at least, known to be at most.
EXACT, AT_LEAST, AT_MOST = 0, 1, 2
BOUND_NAMES = {AT_LEAST: "at least", AT_MOST: "at most"}
#: Diagonal codes per quad: the split along 0-2, along 1-3, or the worse of both.
DIAGONAL_02, DIAGONAL_13, BOTH_DIAGONALS = 0, 1, 2
#: Cells of a quad's (s, t) square are about this many texels of its uv extent wide, at most MAX_CELLS a side.
CELL_TEXELS, MAX_CELLS = 4.0, 16
#: Samples per texel of a cell's uv extent, per side (2 to MAX_CELL_SAMPLES a side).
SAMPLES_PER_TEXEL = 1.0
MAX_CELL_SAMPLES = 32
#: A cell whose bound exceeds the quad's best so far by no more than this (1/255 steps or degrees) is left
#: out: C is then known to within it (the values are meant to be right to one step).
TOLERANCE = 0.5
#: Sample points evaluated together (each costs three bilinear lookups).
POINTS_PER_CHUNK = 1 << 15


def grid(n: int) -> np.ndarray:
    """((n + 1)^2, 2) float64 (s, t) on a regular grid over [0, 1]^2."""
    ticks = np.linspace(0.0, 1.0, n + 1)
    s, t = np.meshgrid(ticks, ticks, indexing="ij")
    return np.stack([s.ravel(), t.ravel()], axis=1)


#: Offsets of the refinement grid around the worst sample, in sample spacings (a 9 x 9 grid over two spacings).
LOCAL = 2.0 * (grid(8) - 0.5)


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
    """(..., 4) float64 weights of the corners at parameters ``st`` (..., 2) of the bilinear patch."""
    s, t = st[..., 0], st[..., 1]
    return np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t], axis=-1)


#: The split's two triangles per diagonal: (i, j, k) and (i, k, m) around the diagonal i-k.
TRIANGLES = {DIAGONAL_02: ((0, 1, 2), (0, 2, 3)), DIAGONAL_13: ((1, 2, 3), (1, 3, 0))}


def corner_barycentrics(xy: np.ndarray, triangle: tuple[int, int, int]) -> np.ndarray:
    """(Q, 4, 3) float64 barycentric coordinates of the four corners of quads ``xy`` (Q, 4, 2) in their
    triangle ``triangle`` (three corner numbers); NaN for a degenerate triangle.

    Barycentric coordinates are affine in the point, and the patch point P(s, t) is the bilinear blend of
    the corners with weights summing to one, so at (s, t) the coordinates of P are the same blend of
    these rows: the split's uv is bilinear in (s, t) per triangle, like the exact uv.
    """
    a, b, c = (xy[:, None, corner] for corner in triangle)

    def cross(u, v):
        return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

    doubled_area = cross(b - a, c - a)  # (Q, 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        w_b = cross(xy - a, c - a) / doubled_area
        w_c = cross(b - a, xy - a) / doubled_area
        weights = np.stack([1.0 - w_b - w_c, w_b, w_c], axis=-1)
    weights[doubled_area[:, 0] == 0] = np.nan
    return weights


def split_uv(weights: np.ndarray, bary_first: np.ndarray, bary_second: np.ndarray, uv_first: np.ndarray,
             uv_second: np.ndarray) -> np.ndarray:
    """(Q, M, 2) the split's uv at the patch points of bilinear ``weights`` (M, 4) or (Q, M, 4): each point in
    the triangle that holds it, of the two with corner barycentrics ``bary_*`` (Q, 4, 3) and corner uv
    ``uv_*`` (Q, 3, 2). A point both or neither hold (a concave quad, whose triangles overlap outside it)
    takes the triangle it lies deeper in (the larger smallest coordinate), as a renderer shows the triangle
    that covers it; a degenerate triangle (NaN) never holds a point, and a point of two degenerate ones
    keeps the exact uv's place (no difference is measured there)."""
    first, second = weights @ bary_first, weights @ bary_second  # (Q, M, 3)
    depth_first, depth_second = _smallest(first), _smallest(second)
    in_first = ~(depth_first < depth_second) & ~np.isnan(depth_first)  # NaN second: first; NaN first: second
    uv = np.where(in_first[..., None], first @ uv_first, second @ uv_second)
    return uv


def _smallest(values: np.ndarray) -> np.ndarray:
    """(...,) the smallest of the last axis (a few entries): elementwise, faster than a reduction over it."""
    smallest = values[..., 0]
    for k in range(1, values.shape[-1]):
        smallest = np.minimum(smallest, values[..., k])
    return smallest


def channel_difference(a: np.ndarray, b: np.ndarray, normal_map: bool) -> np.ndarray:
    """(N,) float64: the largest channel difference between texture samples ``a`` and ``b`` (N, C) of a
    uint8 texture (0-255 units), in 1/255 steps; for a normal map the angle between the decoded normals
    (2 c / 255 - 1 per channel, first three channels), in degrees."""
    if not normal_map:
        difference = np.subtract(a, b)
        np.abs(difference, out=difference)
        largest = difference[:, 0].copy()
        for channel in range(1, difference.shape[1]):  # elementwise: faster than a reduction over a short axis
            np.maximum(largest, difference[:, channel], out=largest)
        return largest.astype(np.float64)
    n_a, n_b = a[:, :3].astype(np.float64) / 127.5 - 1.0, b[:, :3].astype(np.float64) / 127.5 - 1.0
    sine = np.linalg.norm(np.cross(n_a, n_b), axis=1)
    return np.degrees(np.arctan2(sine, np.einsum("ij,ij->i", n_a, n_b)))


def is_convex(xy: np.ndarray) -> np.ndarray:
    """(Q,) bool: the planar quads ``xy`` (Q, 4, 2) turn the same way at every corner (zero turns allowed)."""
    edges = np.roll(xy, -1, axis=1) - xy
    following = np.roll(edges, -1, axis=1)
    turns = edges[:, :, 0] * following[:, :, 1] - edges[:, :, 1] * following[:, :, 0]
    return (turns >= 0).all(axis=1) | (turns <= 0).all(axis=1)


class CreaseTables:
    """What :func:`crease_difference` reads of Q quads, computed once: ``uv`` (Q, 4, 2) where the corners
    read the texture, ``diagonals`` (Q,) their diagonal codes, ``convex`` (Q,) bool, and per diagonal the
    corner barycentrics of its two triangles (Q, 4, 3) and their corners' uv (Q, 3, 2)."""

    def __init__(self, xy: np.ndarray, uv: np.ndarray, diagonals: np.ndarray):
        self.uv, self.diagonals, self.convex = uv, diagonals, is_convex(xy)
        self.triangles = {
            diagonal: [(corner_barycentrics(xy, triangle), uv[:, list(triangle)]) for triangle in pair]
            for diagonal, pair in TRIANGLES.items()}


def crease_difference(texture: PackedTexture, tables: CreaseTables, rows: np.ndarray, st: np.ndarray,
                      normal_map: bool) -> np.ndarray:
    """(q, M) float64: the texture difference between the split's and the exact uv at parameters ``st``
    (M, 2) shared or (q, M, 2) per quad, for the quads ``rows`` (q,) of ``tables``; the worse of the
    diagonals each quad is read along."""
    weights = bilinear_weights(st)  # (M, 4) or (q, M, 4)
    exact = weights @ tables.uv[rows]  # (q, M, 2)
    reference = texture.sample(exact.reshape(-1, 2))
    reference = reference.reshape(*exact.shape[:2], -1)  # (q, M, C)
    worst = np.zeros(exact.shape[:2])
    diagonals = tables.diagonals[rows]
    for diagonal, ((bary_first, uv_first), (bary_second, uv_second)) in tables.triangles.items():
        reads = (diagonals == diagonal) | (diagonals == BOTH_DIAGONALS)
        if reads.all():  # every quad (the default reads both diagonals): no copies of the points
            picked, own, per_quad = slice(None), rows, weights
        elif reads.any():
            picked = np.flatnonzero(reads)
            own, per_quad = rows[picked], weights if weights.ndim == 2 else weights[picked]
        else:
            continue
        split = split_uv(per_quad, bary_first[own], bary_second[own], uv_first[own], uv_second[own])
        unheld = np.isnan(split)
        if unheld.any():  # both triangles degenerate: nothing measured
            split = np.where(unheld, exact[picked], split)
        seen = texture.sample(split.reshape(-1, 2))
        difference = channel_difference(seen, reference[picked].reshape(len(seen), -1), normal_map)
        worst[picked] = np.maximum(worst[picked], difference.reshape(len(own), -1))
    return worst


def _present(counts: np.ndarray) -> list[int]:
    """The distinct values of ``counts`` (n,) small non-negative ints, ascending (``np.unique`` would import
    ``numpy.ma``: 11 ms of a textured check's start-up)."""
    return np.flatnonzero(np.bincount(counts)).tolist() if len(counts) else []


def _chunks(n_quads: int, points_per_quad: int):
    """Slices of quads evaluated together, about :data:`POINTS_PER_CHUNK` sample points each."""
    step = max(1, POINTS_PER_CHUNK // max(points_per_quad, 1))
    return (slice(start, start + step) for start in range(0, n_quads, step))


def _wrapped(start: np.ndarray, stop: np.ndarray, size: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The texel interval [start, stop] (inclusive, any integers) on a repeating axis of ``size`` texels as
    two intervals inside [0, size - 1]: (first, last, used) int64 arrays each, ``used`` False where the
    second is not needed (its bounds then a harmless 0, 0)."""
    span = stop - start
    whole = span >= size - 1
    first = np.where(whole, 0, np.mod(start, size)).astype(np.int64)
    end = first + np.where(whole, size - 1, span).astype(np.int64)
    over = end - size  # >= 0 where the interval runs past the last texel
    second_used = over >= 0
    return [(first, np.minimum(end, size - 1), np.ones(len(start), dtype=bool)),
            (np.zeros(len(start), dtype=np.int64), np.maximum(over, 0), second_used)]


def range_bound(low: np.ndarray, high: np.ndarray, normal_map: bool) -> np.ndarray:
    """(N,) float64: the most two texels whose channels lie in [low, high] (N, C) (0-255) can differ, in C's
    unit: the largest channel range (1/255 steps); for a normal map the largest angle between two decoded
    normals in that box, 2 asin(chord / (2 r)) with chord the box's diagonal and r the shortest decoded vector
    in it (180 degrees where the box holds the zero vector)."""
    if not normal_map:
        return (high - low).max(axis=1)
    low_n, high_n = low[:, :3] / 127.5 - 1.0, high[:, :3] / 127.5 - 1.0
    chord = np.linalg.norm(high_n - low_n, axis=1)
    nearest = np.where((low_n <= 0) & (high_n >= 0), 0.0, np.minimum(np.abs(low_n), np.abs(high_n)))
    shortest = np.linalg.norm(nearest, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(shortest > 0, chord / (2 * shortest), np.inf)
    return np.where(ratio < 1, np.degrees(2 * np.arcsin(np.minimum(ratio, 1.0))), 180.0)


def box_extremes(pyramid: RangePyramid, low_corner: np.ndarray, high_corner: np.ndarray) -> tuple[np.ndarray,
                                                                                                 np.ndarray]:
    """(N, C) float64 per-channel minimum and maximum of ``pyramid``'s image over the texels bilinear
    filtering reaches inside the boxes from ``low_corner`` to ``high_corner`` (N, 2) texel coordinates, each
    box wrapped as repeat wrapping reads it; +inf and -inf for a box with a NaN corner."""
    channels = pyramid.shape[2]
    low, high = np.full((len(low_corner), channels), np.inf), np.full((len(low_corner), channels), -np.inf)
    first, last = np.floor(low_corner), np.floor(high_corner) + 1
    rows = np.flatnonzero(np.isfinite(first).all(axis=1) & np.isfinite(last).all(axis=1))
    if not len(rows):
        return low, high
    height, width = pyramid.shape[:2]
    row_low, row_high = low[rows], high[rows]
    for x0, x1, x_used in _wrapped(first[rows, 0], last[rows, 0], width):
        for y0, y1, y_used in _wrapped(first[rows, 1], last[rows, 1], height):
            used = (x_used & y_used)[:, None]
            box_low, box_high = pyramid.channel_bounds(x0, x1, y0, y1)
            row_low = np.where(used, np.minimum(row_low, box_low), row_low)
            row_high = np.where(used, np.maximum(row_high, box_high), row_high)
    low[rows], high[rows] = row_low, row_high
    return low, high


def crease_bound(texture, low_corner: np.ndarray, high_corner: np.ndarray, shifts: np.ndarray,
                 normal_map: bool) -> np.ndarray:
    """(N,) float64: an upper bound of C over regions whose uv (exact and split) lie in the texel boxes from
    ``low_corner`` to ``high_corner`` (N, 2) and differ by at most ``shifts`` (N, 2) texels across columns and
    rows: the texture's :func:`range_bound` over the box, and for colour and scalar maps also the most the
    bilinear texture changes over that shift (its derivative across columns is a blend of steps to the next
    column, so at most the box's largest such step, and likewise across rows): steps x shifts, the smaller
    of the two. NaN for a box with a NaN corner."""
    low_corner, high_corner = texture.boxed(low_corner, high_corner)  # moved by the map's wrap modes
    low, high = box_extremes(texture.pyramid, low_corner, high_corner)
    with np.errstate(invalid="ignore"):
        bound = range_bound(low, high, normal_map)
        if not normal_map:
            # A box whose texels are all alike is bounded by 0 whatever its steps (finite shifts): only the
            # others read the step pyramids (a flat texture, or a checker's flat squares, reduce none of them).
            rows = np.flatnonzero(~((bound == 0) & np.isfinite(shifts).all(axis=1)))
            (_, across_columns), (_, across_rows) = (box_extremes(slopes, low_corner[rows], high_corner[rows])
                                                     for slopes in texture.slopes)
            bound[rows] = np.minimum(bound[rows], across_columns[:, 0] * shifts[rows, 0]
                                     + across_rows[:, 0] * shifts[rows, 1])
    bound[~np.isfinite(low).all(axis=1)] = np.nan
    return bound


def cell_boxes(tables: CreaseTables, rows: np.ndarray, corners: np.ndarray, width: int,
               height: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Texel boxes holding both uv over each cell, from ``low`` to ``high`` (q, K, 2) texel coordinates, and
    the most (q, K, 2) the split moves the uv over each cell, in texels across columns and rows:
    ``corners`` (K, 4, 2) the (s, t) corners of K cells, for quads ``rows`` (q,).

    Over a cell the exact uv lies in the hull of its values at the cell's corners (a bilinear patch), and
    the split's in the hull of its two triangles' affine maps at them (the patch's points lie in the hull of
    the cell's corner points). Each triangle's uv minus the exact uv is bilinear in (s, t) too, so its
    coordinates' sizes over a cell are largest at its corners: the shift is the largest over corners and
    triangles. A triangle that holds no point of a cell is left out: in a convex quad the split's triangle is
    the side of the diagonal, the sign of the far corner's barycentric coordinate, bilinear over the cell,
    so a cell whose four corners agree on it lies on one side.
    """
    weights = bilinear_weights(corners).reshape(-1, 4)  # (K * 4, 4)
    shape = (len(rows), len(corners), 4, 2)
    exact = texel_coordinates(weights @ tables.uv[rows], width, height).reshape(shape)
    low, high = _corner_extremes(exact)
    shifts = np.zeros((*shape[:2], 2))
    diagonals, convex = tables.diagonals[rows], tables.convex[rows, None]
    for diagonal, pair in tables.triangles.items():
        reads = ((diagonals == diagonal) | (diagonals == BOTH_DIAGONALS))[:, None]
        far = (weights @ pair[0][0][rows][:, :, 1:2])[..., 0].reshape(shape[:3])  # (q, K, 4): j's coordinate
        sides = (np.all(far >= 0, axis=2), np.all(far <= 0, axis=2))  # (q, K) each: the cell is on one side
        for (bary, uv), other_side in zip(pair, sides[::-1]):
            held = reads & ~(convex & other_side)  # (q, K)
            mapped = texel_coordinates((weights @ bary[rows]) @ uv[rows], width, height).reshape(shape)
            mapped = np.where(held[..., None, None], mapped, np.nan)  # NaN (also a degenerate triangle): ignored
            mapped_low, mapped_high = _corner_extremes(mapped)
            low, high = np.fmin(low, mapped_low), np.fmax(high, mapped_high)
            shifts = np.fmax(shifts, _corner_extremes(np.abs(mapped - exact))[1])
    return low, high, shifts


def _corner_extremes(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(q, K, D) the smallest and largest of ``points`` (q, K, 4, D) over their 4 corners, NaN ignored
    (elementwise: a reduction over an axis of 4 is slower)."""
    low = np.fmin(np.fmin(points[:, :, 0], points[:, :, 1]), np.fmin(points[:, :, 2], points[:, :, 3]))
    high = np.fmax(np.fmax(points[:, :, 0], points[:, :, 1]), np.fmax(points[:, :, 2], points[:, :, 3]))
    return low, high


def cells(g: int) -> tuple[np.ndarray, np.ndarray]:
    """The g x g cells of the (s, t) square: their origins (g*g, 2) and their corners (g*g, 4, 2)."""
    origins = grid(g - 1) * (g - 1) / g if g > 1 else np.zeros((1, 2))
    offsets = np.array([[0, 0], [1, 0], [1, 1], [0, 1]]) / g
    return origins, origins[:, None, :] + offsets[None]


def visible_values(texture, xy: np.ndarray, uv: np.ndarray, diagonals: np.ndarray, normal_map: bool,
                   limits: VisibleLimits) -> tuple[np.ndarray, np.ndarray]:
    """C for quads through one texture (the module's passes: bound, cells, samples, refinement).

    Parameters
    ----------
    texture : the decoded texture (:class:`~affinity.textures.decode.DecodedTexture`: its ``pixels``, and
        its ``pyramid`` and ``packed`` texels, built once per texture)
    xy : (Q, 4, 2) float64, the quads' corners in their own planes
    uv : (Q, 4, 2) float64, where the corners read the texture (after any ``-s``/``-o``)
    diagonals : (Q,) int, ``DIAGONAL_02``, ``DIAGONAL_13`` or ``BOTH_DIAGONALS``
    normal_map : the texture holds tangent-space normals (C in degrees)
    limits : the error threshold ends refinement

    Returns
    -------
    values : (Q,) float64, C in 1/255 steps or degrees
    bounds : (Q,) int8, ``EXACT``, ``AT_LEAST`` or ``AT_MOST``
    """
    n = len(xy)
    values, bounds = np.zeros(n), np.full(n, EXACT, dtype=np.int8)
    if n == 0:
        return values, bounds
    height, width = texture.pixels.shape[:2]
    texel_xy = texel_coordinates(uv, width, height)
    pixels = texture.packed
    tables = CreaseTables(xy, uv, diagonals)
    low, high, shifts = cell_boxes(tables, np.arange(n), cells(1)[1], width, height)
    spread = crease_bound(texture, low[:, 0], high[:, 0], shifts[:, 0], normal_map)
    negligible = spread < (min(1.0, limits.warning) if not normal_map else 1e-9)  # NaN: no bound
    values[negligible], bounds[negligible] = spread[negligible], AT_MOST
    todo = np.flatnonzero(~negligible)
    best_st = np.zeros((n, 2))
    extent = np.ptp(texel_xy, axis=1).max(axis=1)
    sides = np.clip(2 ** np.ceil(np.log2(np.maximum(extent / CELL_TEXELS, 1))), 1, MAX_CELLS).astype(int)
    spacing = np.zeros(n)
    for g in _present(sides[todo]):  # one cell count at a time (at most 5), not per quad
        quads = todo[sides[todo] == g]
        origins, corners = cells(g)
        # The cells' corners are the first samples: a quad at the error threshold there is done.
        for part in _chunks(len(quads), (g + 1) ** 2):
            rows = quads[part]
            corner_samples = grid(g)
            difference = crease_difference(pixels, tables, rows, corner_samples, normal_map)
            worst = difference.argmax(axis=1)
            values[rows], best_st[rows] = difference[np.arange(len(rows)), worst], corner_samples[worst]
            spacing[rows] = 1.0 / g
        quads = quads[values[quads] < limits.error]
        # Cells whose texels cannot differ by more than the quad's best so far are left out.
        surviving = []
        for part in _chunks(len(quads), len(origins) * 4):  # a cell's bound costs about four sample points
            rows = quads[part]
            low, high, shifts = cell_boxes(tables, rows, corners, width, height)
            bound = crease_bound(texture, low.reshape(-1, 2), high.reshape(-1, 2), shifts.reshape(-1, 2),
                                 normal_map).reshape(len(rows), -1)
            quad_of, cell_of = np.nonzero(~(bound <= values[rows, None] + TOLERANCE))  # NaN bounds survive
            surviving.append((rows[quad_of], cell_of))
        pair_quads = np.concatenate([q for q, _ in surviving] or [np.zeros(0, dtype=np.int64)])
        pair_cells = np.concatenate([c for _, c in surviving] or [np.zeros(0, dtype=np.int64)])
        samples = np.clip(2 ** np.ceil(np.log2(np.maximum(extent[pair_quads] / g * SAMPLES_PER_TEXEL, 2))), 2,
                          MAX_CELL_SAMPLES).astype(int)
        for k in _present(samples):  # one sample count at a time (at most 5)
            chosen = np.flatnonzero(samples == k)
            local = grid(k) / g  # (M, 2) inside a cell
            for part in _chunks(len(chosen), len(local)):
                pairs = chosen[part]
                rows = pair_quads[pairs]
                st = origins[pair_cells[pairs]][:, None, :] + local[None]  # (p, M, 2)
                difference = crease_difference(pixels, tables, rows, st, normal_map)
                worst = difference.argmax(axis=1)
                found = difference[np.arange(len(pairs)), worst]
                better = found > values[rows]
                np.maximum.at(values, rows, found)
                winners = better & (found == values[rows])
                best_st[rows[winners]] = st[np.flatnonzero(winners), worst[winners]]
                spacing[rows[winners]] = 1.0 / (g * k)
    refine = todo[(values[todo] < limits.error) & (spacing[todo] > 0)]
    for part in _chunks(len(refine), len(LOCAL)):
        rows = refine[part]
        st = np.clip(best_st[rows][:, None, :] + LOCAL[None] * spacing[rows, None, None], 0.0, 1.0)
        values[rows] = np.maximum(values[rows], crease_difference(pixels, tables, rows, st, normal_map).max(axis=1))
    bounds[(bounds == EXACT) & (values >= limits.error)] = AT_LEAST
    return np.round(values, 3), bounds  # thousandths of a step: float32 filtering leaves noise below them
