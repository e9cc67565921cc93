"""Where the refinement meets the rest of the mesh: which edges it splits and which faces it touches.

Edges are identified by the positions of their ends, not by vertex indices, so two faces
that meet on a seam (coincident vertices written twice, as OBJ files do where uv or
colour change) still share the edge: splitting it on one side splits it on the other,
and no crack opens in space where the file had none.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..mesh import Mesh


def welded_vertices(positions: np.ndarray) -> np.ndarray:
    """(V,) int64: one id per distinct position (equal coordinates, equal id)."""
    if len(positions) == 0:
        return np.zeros(0, dtype=np.int64)
    rows = np.ascontiguousarray(positions, dtype=np.float64) + 0.0  # -0.0 and 0.0 weld
    return np.unique(rows.view(np.dtype((np.void, 24))).ravel(), return_inverse=True)[1].reshape(-1).astype(np.int64)


def next_corners(mesh: Mesh) -> np.ndarray:
    """(C,) int64: the corner after each corner in its face (the face's last corner wraps to its first)."""
    face_of = np.repeat(np.arange(mesh.n_faces), mesh.face_sizes)
    corners = np.arange(len(mesh.corner_vertex))
    following = corners + 1
    last = following == mesh.face_start[face_of + 1]
    following[last] = mesh.face_start[face_of[last]]
    return following


@dataclass(eq=False)
class Layout:
    """The edges a refinement splits, per corner of the mesh.

    Attributes
    ----------
    welded : (V,) int64 id of each vertex's position (:func:`welded_vertices`)
    following : (C,) int64 the next corner of every corner's face (:func:`next_corners`)
    start, end : (C,) int64 welded ids of the ends of the edge from each corner to the next
    segments : (C,) int64 segments of the edge from each corner to the next: the refined
        quad's n on every edge of a refined quad or of a face sharing one with it, else 1
    transition_faces : (T,) int64 faces not refined that share an edge with a refined quad
    """

    welded: np.ndarray
    following: np.ndarray
    start: np.ndarray
    end: np.ndarray
    segments: np.ndarray
    transition_faces: np.ndarray

    @property
    def forward(self) -> np.ndarray:
        """(C,) bool: the edge from each corner runs in its canonical direction (lower welded id first)."""
        return self.start <= self.end


def edge_keys(welded_start: np.ndarray, welded_end: np.ndarray, n_vertices: int) -> np.ndarray:
    """(E,) int64 one key per undirected edge between welded ids.

    A collapsed edge (both ends at one position: a pole quad's) is a point, which the
    faces around the pole all touch without sharing an edge there: each gets a key of its
    own (negative), so refining one pole quad splits no other face.
    """
    low, high = np.minimum(welded_start, welded_end), np.maximum(welded_start, welded_end)
    own = -1 - np.arange(low.size).reshape(low.shape)
    return np.where(low == high, own, low * max(n_vertices, 1) + high)


def layout(mesh: Mesh, refine_faces: np.ndarray, refine_n: np.ndarray) -> Layout:
    """Split every edge of the quads ``refine_faces`` (R,) int64 into their ``refine_n`` (R,) segments.

    Refined quads that share an edge must have the same n (:func:`equal_levels`).
    """
    welded = welded_vertices(mesh.positions)
    following = next_corners(mesh)
    start, end = welded[mesh.corner_vertex], welded[mesh.corner_vertex[following]]
    keys = edge_keys(start, end, len(welded))
    refined_corners = (mesh.face_start[refine_faces, None] + np.arange(4)).reshape(-1)
    split_keys, first = np.unique(keys[refined_corners], return_index=True)
    split_n = np.repeat(refine_n, 4)[first]
    segments = np.ones(len(keys), dtype=np.int64)
    if len(split_keys):
        at = np.minimum(np.searchsorted(split_keys, keys), len(split_keys) - 1)
        hit = split_keys[at] == keys
        segments[hit] = split_n[at[hit]]
    face_of = np.repeat(np.arange(mesh.n_faces), mesh.face_sizes)
    touched = np.zeros(mesh.n_faces, dtype=bool)
    touched[face_of[segments > 1]] = True
    touched[refine_faces] = False
    return Layout(welded, following, start, end, segments, np.flatnonzero(touched))


def equal_levels(mesh: Mesh, faces: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Raise the levels ``n`` (R,) of quads ``faces`` (R,) so quads sharing an edge share a level.

    Each connected group of refined quads takes its largest level (the shared edge's
    points must be the same on both sides); a level only ever rises, so every quad still
    meets the threshold it was refined for. Returns (R,) int64.
    """
    n = np.asarray(n, dtype=np.int64).copy()
    if len(faces) < 2:
        return n
    welded = welded_vertices(mesh.positions)
    corners = mesh.face_start[faces, None] + np.arange(4)
    start = welded[mesh.corner_vertex[corners]]
    end = welded[mesh.corner_vertex[corners[:, [1, 2, 3, 0]]]]
    _, edge = np.unique(edge_keys(start, end, len(welded)).reshape(-1), return_inverse=True)
    edge = edge.reshape(-1, 4)
    while True:  # one pass per step across a group: groups of flagged quads are small
        on_edge = np.zeros(edge.max() + 1, dtype=np.int64)
        np.maximum.at(on_edge, edge.reshape(-1), np.repeat(n, 4))
        raised = on_edge[edge].max(axis=1)
        if (raised == n).all():
            return n
        n = raised


def transition_patterns(mesh: Mesh, placed: Layout) -> list[tuple[tuple, np.ndarray]]:
    """The transition faces grouped by their cut's pattern (:func:`affinity.fix.tessellate.transition_polygons`).

    Returns
    -------
    list of (pattern, faces): ``pattern`` the arguments of ``transition_polygons``: the
    segments of each edge, which corners may be a fan's apex (every corner, but only the
    reflex one of a concave quad) and which edges are collapsed; ``faces`` (n,) int64 the
    faces of that pattern in file order.
    """
    from ..geometry import planar_quads

    faces = placed.transition_faces
    if len(faces) == 0:
        return []
    sizes = mesh.face_sizes[faces]
    width = int(sizes.max())
    slot = np.arange(width)
    present = slot < sizes[:, None]
    corners = np.where(present, mesh.face_start[faces, None] + slot, 0)
    counts = np.where(present, placed.segments[corners], 0)
    apexes = present.copy()
    quads = np.flatnonzero(sizes == 4)
    if len(quads):
        reflex = planar_quads(mesh.positions[mesh.corner_vertex[corners[quads, :4]]]).reflex
        concave = reflex.any(axis=1)
        apexes[quads[concave], :4] = reflex[concave]
    collapsed = present & (placed.start[corners] == placed.end[corners])
    keys = np.concatenate([counts, apexes, collapsed], axis=1)
    patterns, which = np.unique(keys, axis=0, return_inverse=True)
    which = which.reshape(-1)
    found = []
    for p, key in enumerate(patterns.tolist()):
        size = int(np.count_nonzero(key[:width]))
        flags = [tuple(bool(a) for a in key[at : at + size]) for at in (width, 2 * width)]
        found.append(((tuple(key[:size]), *flags), faces[which == p]))
    return found
