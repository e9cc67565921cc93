"""Quad-only cuts of a face whose edges carry new points: the refined quads and the faces beside them.

Every edge of the result carries ``c`` segments (its *count*, odd: :mod:`affinity.fix.layout`),
its points at k/c. A quad with counts (c0, c1, c2, c3) on its edges (edge i from corner i to
corner i + 1) and a *level* L (n for a quad refined n x n, 1 for a neighbour) is cut into
quads only, in its parameter square (s, t) (corner 0 at (0, 0), 1 at (1, 0), 2 at (1, 1), 3 at
(0, 1)) and carried onto its bilinear surface by :mod:`affinity.fix.apply`:

* all counts equal to L: the L x L grid (:mod:`affinity.fix.grid`);
* otherwise nested squares (an *onion*): the face's border, then squares inset step by step,
  each side's count moved towards L by at most a factor of 3 per step, and the L x L grid in
  the innermost square. Between two squares each side is a strip of *units*: a plain cell
  (one segment outside, one inside) or a 3-to-1 cell (three segments on one side, one on the
  other, with two points between: the transition template of Schneiders' 3-refinement), so
  each side's count changes by 2 per 3-to-1 cell and a face whose four counts are odd (their
  sum even, as a region meshed with quads needs) always closes. The strips meet at the
  squares' corners along the diagonals, so no corner needs a cell of its own. The rings are thin
  where the face's border has fewer points than the grid (:func:`ring_thickness`).

A face that is not a quad (a triangle, an n-gon) is not cut: it keeps its corners and takes
the points of its split edges as new ones (its corner count grows).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from .grid import weights_at

#: The corners of the parameter square, in the face's order.
SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


@dataclass(frozen=True, eq=False)
class Pattern:
    """The cut of one face pattern.

    Attributes
    ----------
    inner : (K, 2) float64 (s, t) of the points the cut adds inside the face
    polygons : tuple of (k,) tuples of local ids: 0 .. M - 1 the face's ring (corner i, then the
        points of edge i, for i = 0, 1, ...), M + j the inner point j; quads for a quad, the one
        polygon of the ring for any other face
    """

    inner: np.ndarray
    polygons: tuple[tuple[int, ...], ...]


def odd_at_least(value: float) -> int:
    """The smallest odd integer at or above ``value``."""
    n = int(np.ceil(value))
    return n if n % 2 else n + 1


def step_towards(count: int, level: int) -> int:
    """A side's count one square further in: ``count`` moved towards ``level`` by at most a factor of 3
    (odd, as both are)."""
    if count > level:
        return max(level, odd_at_least(count / 3))
    return min(level, 3 * count)


def onion_counts(counts: tuple[int, ...], level: int) -> list[tuple[int, ...]]:
    """The counts of every square from the face's border in to the L x L grid's border (both included)."""
    squares = [tuple(counts)]
    while any(c != level for c in squares[-1]):
        squares.append(tuple(step_towards(c, level) for c in squares[-1]))
    return squares


def _square_points(counts: tuple[int, ...], inset: float) -> np.ndarray:
    """(sum counts, 2) float64 (s, t) of a square inset by ``inset``, in ring order (corner i, then edge i's
    points at k / counts[i])."""
    corners = inset + (1 - 2 * inset) * SQUARE
    rows = []
    for i, count in enumerate(counts):
        k = np.arange(count)[:, None] / count
        rows.append(corners[i] + k * (corners[(i + 1) % 4] - corners[i]))
    return np.concatenate(rows)


def _side(counts: tuple[int, ...], ids: np.ndarray, i: int) -> np.ndarray:
    """(counts[i] + 1,) the ids of side i of a square whose ring (ring order) has ``ids``: corner i to corner i + 1."""
    along = sum(counts[:i]) + np.arange(counts[i] + 1)
    return ids[along % sum(counts)]


def _strip(outer: np.ndarray, inner: np.ndarray, points: np.ndarray, add) -> list[tuple[int, ...]]:
    """The cells between one side of a square (``outer`` (x + 1,) ids) and the same side of the next square in
    (``inner`` (y + 1,) ids): y - r plain cells and r = |x - y| / 2 3-to-1 cells, the latter spread evenly.
    ``add(st)`` adds an inner point and returns its id; ``points`` maps ids to (s, t)."""
    x, y = len(outer) - 1, len(inner) - 1
    wide, narrow = (outer, inner) if x >= y else (inner, outer)
    reducers = (abs(x - y)) // 2
    units = min(x, y)
    # which of the narrow side's segments carry a 3-to-1 cell: spread evenly
    chosen = set(((np.arange(reducers) + 0.5) * units / max(reducers, 1)).astype(int).tolist()) if reducers else set()
    cells, a = [], 0
    for b in range(units):
        if b not in chosen:
            w = (wide[a], wide[a + 1], narrow[b + 1], narrow[b])
            a += 1
        else:
            n0, n1 = points[narrow[b]], points[narrow[b + 1]]
            m1 = add(0.5 * (points[wide[a + 1]] + n0 + (n1 - n0) / 3))
            m2 = add(0.5 * (points[wide[a + 2]] + n0 + 2 * (n1 - n0) / 3))
            cells += [(wide[a], wide[a + 1], m1, narrow[b]), (wide[a + 1], wide[a + 2], m2, m1),
                      (wide[a + 2], wide[a + 3], narrow[b + 1], m2)]
            w = (m1, m2, narrow[b + 1], narrow[b])
            a += 3
        cells.append(w)
    if x < y:  # the cells were built from the inner side: turn them to the face's orientation
        cells = [tuple(reversed(c)) for c in cells]
    return cells


def _grid(ids_of_border: np.ndarray, L: int, K: int, inset: float, add) -> list[tuple[int, ...]]:
    """The L x K grid (L cells along s, K along t) inside a square inset by ``inset`` whose border (counts
    L, K, L, K) has ids ``ids_of_border`` (2 L + 2 K,) in ring order."""
    index = np.empty((K + 1, L + 1), dtype=np.int64)  # [j, i]
    ring = np.concatenate([ids_of_border, ids_of_border[:1]])
    index[0, :] = ring[0 : L + 1]
    index[:, L] = ring[L : L + K + 1]
    index[K, ::-1] = ring[L + K : 2 * L + K + 1]
    index[::-1, 0] = ring[2 * L + K : 2 * L + 2 * K + 1]
    for j in range(1, K):
        for i in range(1, L):
            index[j, i] = add(inset + (1 - 2 * inset) * np.array([i / L, j / K]))
    return [(index[j, i], index[j, i + 1], index[j + 1, i + 1], index[j + 1, i]) for j in range(K) for i in range(L)]


def ring_thickness(rings: int, level: int) -> list[float]:
    """The thickness of each square's ring, from the face's border in, in the parameter square.

    A cell of the outermost ring beside an edge without points spans that whole edge; its split error
    is about its thickness times the quad's, as a grid cell's is about 1/L^2 of it. So ring r (from 0,
    outermost) is 3^r / L^2 thick, its cells spanning 1/3^r of the edge, never thicker than a cell of an
    even spread, 1 / (L + 2 rings).
    """
    even = 1.0 / (level + 2 * rings)
    return [min(3.0**r / level**2, even) for r in range(rings)]


def _strip_sides(counts: tuple[int, ...], level: int) -> tuple[int, ...] | None:
    """The sides a grid with edge strips closes to (:func:`_grid_with_strips`), None when it cannot: one side,
    or two opposite sides (level 3 or more), with more segments than the level and at most three times as
    many; the other sides at the level."""
    differing = tuple(i for i, c in enumerate(counts) if c != level)
    if not differing or any(not level < counts[i] <= 3 * level for i in differing):
        return None
    if len(differing) == 1 or (differing in ((0, 2), (1, 3)) and level >= 3):
        return differing
    return None


def _rotated(pattern: Pattern, counts: tuple[int, ...], r: int) -> Pattern:
    """``pattern`` of the counts rotated by ``r`` (side r first) as the pattern of ``counts``."""
    M = sum(counts)
    offset = sum(counts[:r])
    corners = np.roll(SQUARE, -r, axis=0)  # corner k of the rotated square is corner k + r
    inner = weights_at(pattern.inner) @ corners if len(pattern.inner) else pattern.inner
    polygons = tuple(tuple((v + offset) % M if v < M else v for v in p) for p in pattern.polygons)
    return Pattern(inner, polygons)


def _grid_with_strips(counts: tuple[int, ...], level: int, bottom_and_top: bool) -> Pattern:
    """The L x L grid of a quad whose side 0 (and side 2 when ``bottom_and_top``) has more segments than L:
    the row of cells along that side becomes a strip of plain and 3-to-1 cells (:func:`_strip`) from the
    side's points to the grid's first inner line, whose ends are the neighbouring sides' first points."""
    L = level
    M = sum(counts)
    points = [p for p in _square_points(counts, 0.0)]
    inner: list[np.ndarray] = []

    def add(st) -> int:
        inner.append(np.asarray(st, dtype=np.float64))
        points.append(inner[-1])
        return M + len(inner) - 1

    ring = np.arange(M)
    sides = [_side(counts, ring, i) for i in range(4)]
    index = np.full((L + 1, L + 1), -1, dtype=np.int64)  # [j, i]
    index[:, L] = sides[1]
    index[::-1, 0] = sides[3]
    if not bottom_and_top:
        index[L, ::-1] = sides[2]
    for j in range(1, L):
        for i in range(1, L):
            index[j, i] = add(np.array([i / L, j / L]))
    polygons = _strip(sides[0], index[1], points, add)
    last = L - 1 if bottom_and_top else L
    polygons += [(index[j, i], index[j, i + 1], index[j + 1, i + 1], index[j + 1, i])
                 for j in range(1, last) for i in range(L)]
    if bottom_and_top:
        polygons += _strip(sides[2], index[L - 1, ::-1], points, add)
    return Pattern(np.array(inner).reshape(-1, 2), tuple(tuple(int(v) for v in p) for p in polygons))


@cache
def quad_pattern(counts: tuple[int, int, int, int], level: int) -> Pattern:
    """The quad-only cut of a quad with ``counts`` segments on its edges, refined at ``level`` (module docstring).

    Counts and level are odd. Each cell keeps the face's orientation. The cheapest that applies:

    * a grid of c0 x c1 cells where opposite sides have as many segments, at least the level;
    * the L x L grid whose rows along one side (or two opposite sides) with more segments are strips;
    * the onion.
    """
    c0, c1, c2, c3 = counts
    if c0 == c2 and c1 == c3 and min(counts) >= level:
        return _onion((c0, c1, c0, c1), c0, c1)
    strips = _strip_sides(counts, level)
    if strips is not None:
        r = strips[0]
        rotated = tuple(counts[(i + r) % 4] for i in range(4))
        return _rotated(_grid_with_strips(rotated, level, len(strips) == 2), counts, r)
    return _onion(counts, level, level)


def _onion(counts: tuple[int, ...], level: int, across: int) -> Pattern:
    """Nested squares from ``counts`` in to a ``level`` x ``across`` grid (the module docstring; without
    rings when the counts are the grid's)."""
    squares = [tuple(counts)] if counts == (level, across, level, across) else onion_counts(counts, level)
    rings = len(squares) - 1
    insets = np.cumsum([0.0, *ring_thickness(rings, level)])
    M = sum(counts)
    points = [p for p in _square_points(squares[0], 0.0)]
    inner: list[np.ndarray] = []

    def add(st: np.ndarray) -> int:
        inner.append(np.asarray(st, dtype=np.float64))
        points.append(inner[-1])
        return M + len(inner) - 1

    ids = np.arange(M)
    polygons: list[tuple[int, ...]] = []
    for r in range(rings):
        next_ids = np.array([add(p) for p in _square_points(squares[r + 1], insets[r + 1])])
        for i in range(4):
            polygons += _strip(_side(squares[r], ids, i), _side(squares[r + 1], next_ids, i), points, add)
        ids = next_ids
    polygons += _grid(ids, level, across, insets[-1], add)
    return Pattern(np.array(inner).reshape(-1, 2), tuple(tuple(int(v) for v in p) for p in polygons))


@cache
def face_pattern(counts: tuple[int, ...], level: int) -> Pattern:
    """The cut of any face: :func:`quad_pattern` for a quad, its ring as one polygon for another face."""
    if len(counts) == 4 and (level > 1 or any(c > 1 for c in counts)):
        return quad_pattern(tuple(counts), max(level, 1))
    return Pattern(np.zeros((0, 2)), (tuple(range(sum(counts))),))
