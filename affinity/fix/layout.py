"""Where the refinement meets the rest of the mesh: the points each edge gets and the faces it touches.

Edges are identified by the positions of their ends, not by vertex indices, so two faces
that meet on a seam (coincident vertices written twice, as OBJ files do where uv or
colour change) still share the edge: splitting it on one side splits it on the other,
and no crack opens in space where the file had none.

A refined quad of level n (odd) puts points at k/n along each of its edges. An edge takes the
highest level of the refined quads on it, its *count* c, and its points are the k/c
(:func:`edge_parameters`), the same for every face on the edge, so both sides meet point for
point. An edge of a face the fix leaves keeps no point: the face is never re-cut. Every count
is odd, so every quad's four counts sum to an even number and it closes with quads
(:mod:`affinity.fix.patterns`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..mesh import Mesh

#: The highest level a refinement takes (a sanity bound: the cap is --max-refine).
MAX_LEVEL = 63


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


def edge_parameters(count: int) -> np.ndarray:
    """(count - 1,) float64: the points of an edge cut in ``count`` segments, k / count strictly between 0 and 1."""
    return np.arange(1, count) / count


@dataclass(eq=False)
class Layout:
    """The points a refinement puts on each edge, per corner of the mesh.

    Attributes
    ----------
    following : (C,) int64 the next corner of every corner's face (:func:`next_corners`)
    start, end : (C,) int64 welded ids of the ends of the edge from each corner to the next
    counts : (C,) int64 segments of the edge from each corner to the next (1: no point on it; odd)
    level : (F,) int64 every face's refinement level, 0 for a face not refined
    transition_faces : (T,) int64 faces not refined that share an edge with a refined quad
    """

    following: np.ndarray
    start: np.ndarray
    end: np.ndarray
    counts: np.ndarray
    level: np.ndarray
    transition_faces: np.ndarray

    @property
    def points(self) -> np.ndarray:
        """(C,) int64: how many points the edge from each corner gets."""
        return self.counts - 1


def layout(mesh: Mesh, refine_faces: np.ndarray, refine_n: np.ndarray, frozen: np.ndarray | None = None) -> Layout:
    """Put the points of the quads ``refine_faces`` (R,) int64 refined at levels ``refine_n`` (R,) on their edges.

    An edge takes the highest level of the refined quads on it (odd levels: every quad's counts are odd, so
    every quad closes with quads, :mod:`affinity.fix.patterns`); an edge of a face in ``frozen`` (k,) int64
    (faces left as they are) keeps its ends only, and the refined quad beside it closes to it.
    """
    if len(refine_n) and int(np.max(refine_n)) > MAX_LEVEL:
        raise ValueError(f"refinement levels go up to {MAX_LEVEL}")
    welded = welded_vertices(mesh.positions)
    following = next_corners(mesh)
    start, end = welded[mesh.corner_vertex], welded[mesh.corner_vertex[following]]
    keys = edge_keys(start, end, len(welded))
    face_of = np.repeat(np.arange(mesh.n_faces), mesh.face_sizes)
    refined_corners = (mesh.face_start[refine_faces, None] + np.arange(4)).reshape(-1)
    split_keys, edge = np.unique(keys[refined_corners], return_inverse=True)
    most = np.ones(len(split_keys), dtype=np.int64)
    np.maximum.at(most, edge.reshape(-1), np.repeat(refine_n, 4).astype(np.int64))
    if frozen is not None and len(frozen) and len(split_keys):
        frozen_corners = np.flatnonzero(np.isin(face_of, frozen))
        at = np.minimum(np.searchsorted(split_keys, keys[frozen_corners]), len(split_keys) - 1)
        most[at[split_keys[at] == keys[frozen_corners]]] = 1
    counts = np.ones(len(keys), dtype=np.int64)
    if len(split_keys):
        at = np.minimum(np.searchsorted(split_keys, keys), len(split_keys) - 1)
        hit = split_keys[at] == keys
        counts[hit] = most[at[hit]]
    level = np.zeros(mesh.n_faces, dtype=np.int64)
    level[refine_faces] = refine_n
    touched = np.zeros(mesh.n_faces, dtype=bool)
    touched[face_of[counts > 1]] = True
    touched[refine_faces] = False
    return Layout(following, start, end, counts, level, np.flatnonzero(touched))


def face_patterns(mesh: Mesh, placed: Layout, faces: np.ndarray) -> list[tuple[tuple, np.ndarray]]:
    """The faces ``faces`` (n,) int64 grouped by their cut: ``(counts per edge, level)``, the arguments of
    :func:`affinity.fix.patterns.face_pattern` (level 1 for a face not refined).

    Returns
    -------
    list of (pattern, faces): ``faces`` (m,) int64 the faces of that pattern in file order.
    """
    if len(faces) == 0:
        return []
    sizes = mesh.face_sizes[faces]
    width = int(sizes.max())
    slot = np.arange(width)
    present = slot < sizes[:, None]
    corners = np.where(present, mesh.face_start[faces, None] + slot, 0)
    counts = np.where(present, placed.counts[corners], 0)
    keys = np.concatenate([np.maximum(placed.level[faces, None], 1), counts], axis=1)
    first, which = unique_rows(keys)
    found = []
    for p, key in enumerate(keys[first].tolist()):
        edges = tuple(c for c in key[1:] if c > 0)
        found.append(((edges, key[0]), faces[which == p]))
    return found
