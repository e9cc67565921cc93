"""Fixed-point screen triangles and their per-row spans of covered pixels.

Coverage is decided with exact integer edge functions: corners are snapped to
1/256 pixel (``SUBPIXEL_BITS``), and the pixel centres of a row covered by a
triangle form one run of columns [c_lo, c_hi] found by an exact floor (or
ceiling) of a quotient per edge. The integers are held in float64, where the
arithmetic is faster than int64 in NumPy and still exact (all below 2^53).
Fragments are then generated from these spans with ``np.repeat`` and
``np.arange`` (``expand_ranges``): no bounding-box grids and no loop per
triangle.

Fill rule (top-left): a pixel centre exactly on an edge belongs to the
triangle only if the edge is a top edge (horizontal, interior below) or a left
edge (interior to its right). An edge shared by two triangles on opposite
sides is a top-left edge for exactly one of them, so a closed mesh covers every
pixel centre once: no holes, no double hits.

Pixel convention: row 0 is the top row, pixel (r, c) has its centre at
NDC x = (c + 0.5) * 2 / W - 1, y = 1 - (r + 0.5) * 2 / H. In the fixed-point
frame X = 256 * (column coordinate), Y = 256 * (row coordinate), y points down.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SUBPIXEL_BITS = 8
SUB = 1 << SUBPIXEL_BITS
HALF = SUB // 2
# How far beyond each image border (in pixels) corners may lie after clipping:
# large enough that guard-band clipping almost never cuts anything visible,
# small enough that, for images up to MAX_SIZE pixels, fixed-point coordinates
# stay below 2^25 and every edge function value below 2^53 (exact in float64).
GUARD_PIXELS = 1 << 14
MAX_SIZE = 1 << 16


def guard_planes(width, height) -> np.ndarray:
    """Clip planes (4, 4) of the guard band |x| <= gx w, |y| <= gy w around the image."""
    gx = 1.0 + 2.0 * GUARD_PIXELS / width
    gy = 1.0 + 2.0 * GUARD_PIXELS / height
    return np.array([[-1.0, 0, 0, gx], [1.0, 0, 0, gx], [0, -1.0, 0, gy], [0, 1.0, 0, gy]])


@dataclass
class ScreenTriangles:
    """Snapped triangles set up for span generation (T triangles).

    Edge e (0..2) of a triangle admits pixel (r, c) when
    ``edge_r[e] * r + edge_k[e] - edge_c[e] * c >= 0``; the arrays are (3, T)
    float64 holding integers below 2^53, so every product, sum and floor of a
    quotient is exact. The top-left bias is folded into ``edge_k``. Edges are
    ordered so that slot 0 bounds the span on the left (``edge_c < 0``), slot
    1 on the right (``edge_c > 0``) and slot 2 is the third edge, of either
    kind or horizontal (``edge_c == 0``). ``row0``/``row1`` (T,) int64 are the
    first and last image rows whose centres can be inside, ``size`` (T,)
    float64 an estimate of the number of covered pixels.
    """

    edge_r: np.ndarray
    edge_k: np.ndarray
    edge_c: np.ndarray
    row0: np.ndarray
    row1: np.ndarray
    size: np.ndarray

    @classmethod
    def concatenate(cls, parts) -> ScreenTriangles:
        """One set of the triangles of several, in order."""
        parts = list(parts)
        if not parts:
            empty = np.zeros((3, 0))
            return cls(empty, empty, empty, np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0))
        return cls(
            *(np.concatenate([getattr(p, name) for p in parts], axis=-1) for name in cls.__dataclass_fields__)
        )


def snap_triangles(tri, orientation, width, height):
    """Snap clip-space triangles (w > 0) to fixed point and set up their edges.

    Parameters
    ----------
    tri : (4, 3, T) float64
        Clip-space corners (component, corner, triangle) with w > 0 and inside
        the guard band.
    orientation : (T,) float
        +1 where the triangle is counter-clockwise in NDC (front-facing), -1
        where clockwise: the sign of its homogeneous determinant.
    width, height : int
        At most ``MAX_SIZE``.

    Returns
    -------
    triangles : ScreenTriangles
        For the kept triangles, wound so that the interior is where every edge
        function is positive.
    kept : (T,) bool
        False where snapping collapsed the triangle or flipped its orientation
        (slivers far below a pixel), or where it covers no image row.
    """
    w = tri[3]
    X = np.rint((tri[0] / w + 1.0) * (0.5 * width * SUB))  # (3, T)
    Y = np.rint((1.0 - tri[1] / w) * (0.5 * height * SUB))
    area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0])
    # y points down in the fixed-point frame, so a front-facing triangle has area < 0.
    kept = area * np.sign(orientation) < 0
    flip = area < 0
    X[1], X[2] = np.where(flip, X[2], X[1]), np.where(flip, X[1], X[2])
    Y[1], Y[2] = np.where(flip, Y[2], Y[1]), np.where(flip, Y[1], Y[2])

    row0 = np.maximum(np.ceil((Y.min(axis=0) - HALF) / SUB), 0).astype(np.int64)
    row1 = np.minimum(np.floor((Y.max(axis=0) - HALF) / SUB), height - 1).astype(np.int64)
    col0 = np.maximum(np.ceil((X.min(axis=0) - HALF) / SUB), 0)
    col1 = np.minimum(np.floor((X.max(axis=0) - HALF) / SUB), width - 1)
    kept &= (row0 <= row1) & (col0 <= col1)

    X, Y = np.compress(kept, X, axis=1), np.compress(kept, Y, axis=1)
    dx = X[[1, 2, 0]] - X
    dy = Y[[1, 2, 0]] - Y
    top_left = (dy < 0) | ((dy == 0) & (dx > 0))
    edge_k = dx * (HALF - Y) - dy * (HALF - X) - (~top_left)
    # Slots: a left edge (dy < 0), a right edge (dy > 0), then the third one;
    # every triangle of nonzero area has at least one edge of each kind.
    left = np.where(dy[0] < 0, 0, np.where(dy[1] < 0, 1, 2))
    right = np.where(dy[0] > 0, 0, np.where(dy[1] > 0, 1, 2))
    pick = np.stack([left, right, 3 - left - right]), np.arange(X.shape[1])
    triangles = ScreenTriangles(
        edge_r=dx[pick] * SUB,
        edge_k=edge_k[pick],
        edge_c=dy[pick] * SUB,
        row0=row0[kept],
        row1=row1[kept],
        # The area counts what lies off the image too (a triangle reaching into the guard band, a corner just
        # behind the eye): no more than the image rows and columns it spans are covered.
        size=np.minimum((0.5 / SUB**2) * np.abs(area[kept]) + (col1 - col0 + 1)[kept],
                        ((row1 - row0 + 1) * (col1 - col0 + 1))[kept]),
    )
    return triangles, kept


def row_spans(triangles: ScreenTriangles, tri, row, width):
    """Covered columns of image row ``row`` (P,) in triangle ``tri`` (P,).

    Returns ``c_lo, c_hi`` (P,) int64, inclusive and clamped to the image;
    ``c_lo > c_hi`` where the row misses the triangle.
    """
    # All three edges at once, (3, P), in place: the pairs are as many as the fragments' spans.
    K = np.take(triangles.edge_r, tri, axis=1)
    K *= row.astype(np.float64)  # once: a mixed int-float product casts every element
    K += np.take(triangles.edge_k, tri, axis=1)
    c = np.take(triangles.edge_c, tri, axis=1)
    horizontal_out = (c[2] == 0) & (K[2] < 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        K /= c
    c_lo, c_hi, third = K
    np.ceil(c_lo, out=c_lo)
    np.floor(c_hi, out=c_hi)
    np.maximum(c_lo, np.where(c[2] < 0, np.ceil(third), 0.0), out=c_lo)
    np.minimum(c_hi, np.where(c[2] > 0, np.floor(third), width - 1.0), out=c_hi)
    c_hi[horizontal_out] = -1.0
    return np.maximum(c_lo, 0.0).astype(np.int64), np.minimum(c_hi, width - 1.0).astype(np.int64)


def expand_ranges(counts):
    """Enumerate ``counts[i]`` items for every i without a Python loop.

    counts : (P,) int64 >= 0. Returns ``owner`` (sum,) int64, the i each item
    belongs to, and ``rank`` (sum,) int64, its position 0..counts[i]-1.
    """
    starts = np.cumsum(counts) - counts
    owner = np.repeat(np.arange(counts.size), counts)
    return owner, np.arange(owner.size) - np.repeat(starts, counts)
