"""The cut of every face the fix replaces: the refined quad's grid, and the faces re-cut to meet its points.

A refined quad of level n becomes the n x n cells of its grid (:mod:`affinity.fix.grid`);
where an edge of it also carries another quad's points (a neighbour refined at another
level), each cell along that edge is cut like a transition face over the points on its
outer side, fanned from its inner corner (:func:`face_polygons`).

Transition faces: a face beside refined quads, re-cut so it meets every new edge point.

A face whose edges carry new points (an edge shared with a refined quad, split into n)
is replaced by triangles (and quads) over its *ring*: its corners and, after each
corner, the points on the edge that leaves it, in the face's own order. No vertex is
added inside the face except in the last resort below, so the values on the shared
edge are the edge's own linear blend on both sides and nothing cracks.

Three cuts, the first that applies:

* a fan from an *apex*, a corner whose two edges carry no point (for a concave quad
  only its reflex corner, from which the whole quad is seen): M - 2 triangles for a
  ring of M points, so a quad with one edge split in n gains n faces;
* a quad whose two opposite edges carry points (and the other two none): a strip
  between them, quads where the two edges carry as many points, else a zipper of
  triangles that advances along whichever edge lags in its parameter;
* otherwise a fan from the face's centre (the bilinear centre of a quad, the corner
  mean of another face), M triangles.

A cut depends only on the face's size, its edges' point counts and where an apex may
stand, so it is built once per such *pattern* as local polygons over ring positions
(:func:`transition_polygons`) and applied to every face of the pattern at once.
"""

from __future__ import annotations

import bisect
import math
from functools import cache

from .layout import edge_parameters

#: Ring position of the centre vertex: one past the ring (``len(ring)``) in a pattern's polygons.
CENTRE = -1


def ring_corners(counts: tuple[int, ...]) -> list[int]:
    """Ring position of every corner: corner i follows its predecessors' edges' points."""
    positions, at = [], 0
    for m in counts:
        positions.append(at)
        at += m
    return positions


@cache
def transition_polygons(counts: tuple[int, ...], apex_allowed: tuple[bool, ...],
                        collapsed: tuple[bool, ...]) -> tuple[tuple[int, ...], ...]:
    """The cut of a face with ``counts[i]`` segments on edge i (corner i to corner i + 1).

    Parameters
    ----------
    counts : (k,) segments per edge, 1 for an edge without points.
    apex_allowed : (k,) which corners may be a fan's apex.
    collapsed : (k,) edges whose two corners share a position (a pole quad's): the corners
        count as one point, so a polygon that would hold both keeps one (a triangle holding
        both, which covers nothing, is dropped).

    Returns
    -------
    Polygons as ring positions (0 .. M - 1, M = sum(counts)), :data:`CENTRE` for the
    centre vertex; each keeps the face's orientation.
    """
    corner = ring_corners(counts)
    same = {corner[(i + 1) % len(counts)]: corner[i] for i in range(len(counts)) if collapsed[i]}
    kept = []
    for polygon in _cut(counts, apex_allowed):
        distinct = [r for r in polygon if not (r in same and same[r] in polygon)]
        if len(distinct) >= 3:
            kept.append(tuple(distinct))
    return tuple(kept)


def _cut(counts: tuple[int, ...], apex_allowed: tuple[bool, ...]) -> tuple[tuple[int, ...], ...]:
    """:func:`transition_polygons` before collapsed edges are merged."""
    k, M = len(counts), sum(counts)
    corner = ring_corners(counts)
    for i in range(k):
        if apex_allowed[i] and counts[i] == 1 and counts[i - 1] == 1:
            apex = corner[i]
            return tuple((apex, (apex + r) % M, (apex + r + 1) % M) for r in range(1, M - 1))
    if k == 4:
        for first in (0, 1):
            if counts[first + 1] == 1 and counts[(first + 3) % 4] == 1:
                return _strip(counts, corner, first)
    return tuple((r, (r + 1) % M, CENTRE) for r in range(M))


def _strip(counts: tuple[int, ...], corner: list[int], first: int) -> tuple[tuple[int, ...], ...]:
    """A quad's cut between its split edges ``first`` and ``first + 2``: quads when they carry
    as many segments, else a zipper of triangles."""
    M = sum(counts)
    a_count, b_count = counts[first], counts[first + 2]
    along_a = [corner[first] + i for i in range(a_count + 1)]  # corner first -> corner first + 1
    # edge first + 2 runs corner first + 2 -> first + 3; read backwards it runs beside edge first
    along_b = [(corner[first + 2] + b_count - j) % M for j in range(b_count + 1)]
    if a_count == b_count:
        return tuple((along_a[i], along_a[i + 1], along_b[i + 1], along_b[i]) for i in range(a_count))
    polygons, i, j = [], 0, 0
    while i < a_count or j < b_count:
        if j == b_count or (i < a_count and (i + 1) * b_count <= (j + 1) * a_count):
            polygons.append((along_a[i], along_a[i + 1], along_b[j]))
            i += 1
        else:
            polygons.append((along_a[i], along_b[j + 1], along_b[j]))
            j += 1
    return tuple(polygons)


@cache
def face_polygons(level: int, edge_levels: tuple[int, ...], apex_allowed: tuple[bool, ...],
                  collapsed: tuple[bool, ...]) -> tuple[tuple[int, ...], ...]:
    """The cut of a face by its pattern (:func:`affinity.fix.layout.face_patterns`).

    Local ids: 0 .. M - 1 the ring (corners, and after each its edge's points,
    :func:`affinity.fix.layout.edge_parameters` of ``edge_levels``), then, for a refined
    quad (``level`` n > 0), its grid's inner points M .. M + (n - 1)^2 - 1 in
    :func:`affinity.fix.grid.interior_points` order; :data:`CENTRE` for a centre vertex.
    """
    params = [edge_parameters(bits) for bits in edge_levels]
    counts = tuple(len(p) + 1 for p in params)
    if level == 0:
        return transition_polygons(counts, apex_allowed, collapsed)
    n, corner, M = level, ring_corners(counts), sum(counts)
    # parameters as integers over one common denominator: exact, and fast to compare
    scale = math.lcm(n, *(t.denominator for p in params for t in p))
    numerators = [[int(t * scale) for t in p] for p in params]
    index = [{t: corner[edge] + 1 + k for k, t in enumerate(p)} for edge, p in enumerate(numerators)]
    step = scale // n

    def grid_point(i: int, j: int) -> int:
        if 0 < i < n and 0 < j < n:
            return M + (j - 1) * (n - 1) + (i - 1)
        if j == 0:
            return corner[0] if i == 0 else corner[1] if i == n else index[0][i * step]
        if j == n:
            return corner[3] if i == 0 else corner[2] if i == n else index[2][scale - i * step]
        return index[3][scale - j * step] if i == 0 else index[1][j * step]

    def between(edge: int, a: int, b: int) -> list[int]:
        """The ring ids of the points of ``edge`` strictly between parameters a < b (numerators), ascending."""
        p = numerators[edge]
        return [corner[edge] + 1 + k for k in range(bisect.bisect_right(p, a), bisect.bisect_left(p, b))]

    polygons = []
    for j in range(n):
        for i in range(n):
            sides = [
                between(0, i * step, (i + 1) * step) if j == 0 else [],
                between(1, j * step, (j + 1) * step) if i == n - 1 else [],
                between(2, scale - (i + 1) * step, scale - i * step) if j == n - 1 else [],
                between(3, scale - (j + 1) * step, scale - j * step) if i == 0 else [],
            ]
            cell = [grid_point(i, j), grid_point(i + 1, j), grid_point(i + 1, j + 1), grid_point(i, j + 1)]
            if not any(sides):
                polygons.append(tuple(cell))
                continue
            ring = [point for k in range(4) for point in (cell[k], *sides[k])]
            cut = transition_polygons(tuple(len(side) + 1 for side in sides), (True,) * 4, (False,) * 4)
            polygons += [tuple(ring[r] for r in polygon) for polygon in cut]
    return tuple(polygons)
