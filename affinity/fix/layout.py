"""Where the refinement meets the rest of the mesh: the points each edge gets and the faces it touches.

Edges are identified by the positions of their ends, not by vertex indices, so two faces
that meet on a seam (coincident vertices written twice, as OBJ files do where uv or
colour change) still share the edge: splitting it on one side splits it on the other,
and no crack opens in space where the file had none.

A refined quad of level n puts points at k/n along each of its edges. An edge keeps the
points of every refined quad on it: its *levels* (a bit set, bit n for level n) decide
its points, the union of the k/n (:func:`edge_parameters`), the same for every face on
the edge, so both sides meet point for point. Quads refined at different levels keep
their own levels; only the cells of their grids along the shared edge take the other's
points too (:func:`affinity.fix.tessellate.face_polygons`).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cache

import numpy as np

from ..mesh import Mesh

#: Levels are kept as bits of an int64.
MAX_LEVEL = 62


def unique_rows(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct rows of (n, k) ``rows``, by a sort on the columns (``np.unique(axis=0)`` sorts them as
    raw bytes, several times slower on large arrays; equal numbers are equal here, -0.0 and 0.0 too).

    Returns
    -------
    first : (U,) int64 a row of each distinct row, in the rows' sorted order
    inverse : (n,) int64 the distinct row of every row
    """
    if len(rows) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    order = np.lexsort(rows.T[::-1])
    ordered = rows[order]
    new = np.ones(len(rows), dtype=bool)
    new[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    inverse = np.empty(len(rows), dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    return order[new], inverse


def welded_vertices(positions: np.ndarray) -> np.ndarray:
    """(V,) int64: one id per distinct position (equal coordinates, equal id)."""
    return unique_rows(np.asarray(positions, dtype=np.float64))[1]


def next_corners(mesh: Mesh) -> np.ndarray:
    """(C,) int64: the corner after each corner in its face (the face's last corner wraps to its first)."""
    face_of = np.repeat(np.arange(mesh.n_faces), mesh.face_sizes)
    corners = np.arange(len(mesh.corner_vertex))
    following = corners + 1
    last = following == mesh.face_start[face_of + 1]
    following[last] = mesh.face_start[face_of[last]]
    return following


def edge_keys(welded_start: np.ndarray, welded_end: np.ndarray, n_vertices: int) -> np.ndarray:
    """(E,) int64 one key per undirected edge between welded ids.

    A collapsed edge (both ends at one position: a pole quad's) is a point, which the
    faces around the pole all touch without sharing an edge there: each gets a key of its
    own (negative), so refining one pole quad splits no other face.
    """
    low, high = np.minimum(welded_start, welded_end), np.maximum(welded_start, welded_end)
    own = -1 - np.arange(low.size).reshape(low.shape)
    return np.where(low == high, own, low * max(n_vertices, 1) + high)


@cache
def edge_parameters(levels: int) -> tuple[Fraction, ...]:
    """The points of an edge whose refined quads have the level bits ``levels``: every k/n strictly
    between 0 and 1 for each level n, once, ascending (symmetric: t and 1 - t both appear)."""
    found = {Fraction(k, n) for n in range(2, MAX_LEVEL + 1) if levels >> n & 1 for k in range(1, n)}
    return tuple(sorted(found))


@dataclass(eq=False)
class Layout:
    """The points a refinement puts on each edge, per corner of the mesh.

    Attributes
    ----------
    following : (C,) int64 the next corner of every corner's face (:func:`next_corners`)
    start, end : (C,) int64 welded ids of the ends of the edge from each corner to the next
    levels : (C,) int64 level bits of the edge from each corner to the next (0: no point on it)
    level : (F,) int64 every face's refinement level, 0 for a face not refined
    transition_faces : (T,) int64 faces not refined that share an edge with a refined quad
    """

    following: np.ndarray
    start: np.ndarray
    end: np.ndarray
    levels: np.ndarray
    level: np.ndarray
    transition_faces: np.ndarray

    @property
    def points(self) -> np.ndarray:
        """(C,) int64: how many points the edge from each corner gets."""
        bits, which = np.unique(self.levels, return_inverse=True)
        counts = np.array([len(edge_parameters(b)) for b in bits.tolist()], dtype=np.int64)
        return counts[which.reshape(-1)]


def layout(mesh: Mesh, refine_faces: np.ndarray, refine_n: np.ndarray) -> Layout:
    """Put the points of the quads ``refine_faces`` (R,) int64 refined at levels ``refine_n`` (R,) on their edges."""
    if len(refine_n) and int(np.max(refine_n)) > MAX_LEVEL:
        raise ValueError(f"refinement levels go up to {MAX_LEVEL}")
    welded = welded_vertices(mesh.positions)
    following = next_corners(mesh)
    start, end = welded[mesh.corner_vertex], welded[mesh.corner_vertex[following]]
    keys = edge_keys(start, end, len(welded))
    refined_corners = (mesh.face_start[refine_faces, None] + np.arange(4)).reshape(-1)
    split_keys, edge = np.unique(keys[refined_corners], return_inverse=True)
    bits = np.zeros(len(split_keys), dtype=np.int64)
    np.bitwise_or.at(bits, edge.reshape(-1), np.left_shift(1, np.repeat(refine_n, 4)).astype(np.int64))
    levels = np.zeros(len(keys), dtype=np.int64)
    if len(split_keys):
        at = np.minimum(np.searchsorted(split_keys, keys), len(split_keys) - 1)
        hit = split_keys[at] == keys
        levels[hit] = bits[at[hit]]
    level = np.zeros(mesh.n_faces, dtype=np.int64)
    level[refine_faces] = refine_n
    face_of = np.repeat(np.arange(mesh.n_faces), mesh.face_sizes)
    touched = np.zeros(mesh.n_faces, dtype=bool)
    touched[face_of[levels > 0]] = True
    touched[refine_faces] = False
    return Layout(following, start, end, levels, level, np.flatnonzero(touched))


def face_patterns(mesh: Mesh, placed: Layout, faces: np.ndarray) -> list[tuple[tuple, np.ndarray]]:
    """The faces ``faces`` (n,) int64 grouped by the pattern of their cut
    (the arguments of :func:`affinity.fix.tessellate.face_polygons`).

    Returns
    -------
    list of (pattern, faces): ``pattern`` = (level, edge level bits per edge, which corners may
    be a fan's apex (every corner, but only the reflex one of a concave quad), which edges are
    collapsed); ``faces`` (m,) int64 the faces of that pattern in file order.
    """
    from ..geometry import planar_quads

    if len(faces) == 0:
        return []
    sizes = mesh.face_sizes[faces]
    width = int(sizes.max())
    slot = np.arange(width)
    present = slot < sizes[:, None]
    corners = np.where(present, mesh.face_start[faces, None] + slot, 0)
    bits = np.where(present, placed.levels[corners], -1)
    apexes = present.copy()
    quads = np.flatnonzero(sizes == 4)
    if len(quads):
        reflex = planar_quads(mesh.positions[mesh.corner_vertex[corners[quads, :4]]]).reflex
        concave = reflex.any(axis=1)
        apexes[quads[concave], :4] = reflex[concave]
    collapsed = present & (placed.start[corners] == placed.end[corners])
    refined = placed.level[faces] > 0
    apexes[refined], collapsed[refined] = False, False  # a refined quad's cut needs neither
    keys = np.concatenate([placed.level[faces, None], bits, apexes, collapsed], axis=1)
    first, which = unique_rows(keys)
    found = []
    for p, key in enumerate(keys[first].tolist()):
        edges = key[1 : 1 + width]
        size = sum(b >= 0 for b in edges)
        flags = [tuple(bool(a) for a in key[at : at + size]) for at in (1 + width, 1 + 2 * width)]
        found.append(((key[0], tuple(edges[:size]), *flags), faces[which == p]))
    return found
