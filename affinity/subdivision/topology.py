"""The connectivity one level of uniform subdivision reads: each face's corners, the undirected edges with
their faces, and what lies around a vertex, as flat arrays (no Python loop over faces).

A corner ``c`` of face ``f`` is followed by ``next[c]`` and preceded by ``prev[c]`` in the face; the side from
``c`` to ``next[c]`` is edge ``corner_edge[c]``. Faces are taken as consistently oriented (each interior
edge is walked once each way), as OpenSubdiv's Far takes them.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

#: Sharpness at or above which an edge or vertex is infinitely sharp (OpenSubdiv's Sdc::Crease::SHARPNESS_INFINITE).
INFINITE = 10.0


def decay(sharpness: np.ndarray) -> np.ndarray:
    """(n,) float64 sharpness one level down under the uniform creasing rule: s - 1, at least 0, infinite
    sharpness staying infinite (Sdc::Crease::SubdivideUniformSharpness; DeRose, Kass & Truong 1998, sec. 3)."""
    return np.where(sharpness >= INFINITE, sharpness, np.maximum(sharpness - 1.0, 0.0))


@dataclass(eq=False)
class Topology:
    """One level's faces and edges.

    Attributes
    ----------
    face_start : (F + 1,) int64
        Face ``f`` owns corners ``face_start[f]:face_start[f + 1]``.
    corner_vertex : (C,) int64
    n_vertices : int
    """

    face_start: np.ndarray
    corner_vertex: np.ndarray
    n_vertices: int

    @property
    def n_faces(self) -> int:
        return len(self.face_start) - 1

    @cached_property
    def face_size(self) -> np.ndarray:
        """(F,) int64 corners of each face."""
        return np.diff(self.face_start)

    @cached_property
    def corner_face(self) -> np.ndarray:
        """(C,) int64 face of each corner."""
        return np.repeat(np.arange(self.n_faces), self.face_size)

    @cached_property
    def corner_local(self) -> np.ndarray:
        """(C,) int64 position of each corner in its face."""
        return np.arange(len(self.corner_vertex)) - self.face_start[self.corner_face]

    @cached_property
    def next(self) -> np.ndarray:
        """(C,) int64 the next corner of the same face."""
        following = np.arange(1, len(self.corner_vertex) + 1)
        following[self.face_start[1:] - 1] = self.face_start[:-1]
        return following

    @cached_property
    def prev(self) -> np.ndarray:
        """(C,) int64 the previous corner of the same face."""
        previous = np.arange(-1, len(self.corner_vertex) - 1)
        previous[self.face_start[:-1]] = self.face_start[1:] - 1
        return previous

    def given_edges(self, edge_vertices: np.ndarray, corner_edge: np.ndarray) -> Topology:
        """The topology with its edges known already (a refined level's, :func:`refine._child_topology`):
        ``edge_vertices`` (E, 2) int64, the lower vertex first; ``corner_edge`` (C,) int64."""
        self.__dict__["_edges"] = (edge_vertices, corner_edge)
        return self

    @cached_property
    def _edges(self) -> tuple[np.ndarray, np.ndarray]:
        a, b = self.corner_vertex, self.corner_vertex[self.next]
        key = np.minimum(a, b) * np.int64(self.n_vertices) + np.maximum(a, b)
        unique, corner_edge = np.unique(key, return_inverse=True)
        vertices = np.stack([unique // self.n_vertices, unique % self.n_vertices], axis=1)
        return vertices, corner_edge.ravel()

    @property
    def edge_vertices(self) -> np.ndarray:
        """(E, 2) int64 the two vertices of each edge, the lower first."""
        return self._edges[0]

    @property
    def corner_edge(self) -> np.ndarray:
        """(C,) int64 the edge from each corner to the next corner of its face."""
        return self._edges[1]

    @property
    def n_edges(self) -> int:
        return len(self.edge_vertices)

    @cached_property
    def edge_face_count(self) -> np.ndarray:
        """(E,) int64 faces on each edge: 1 on a boundary, 2 inside, more where non-manifold."""
        return np.bincount(self.corner_edge, minlength=self.n_edges)

    @cached_property
    def corner_rank(self) -> np.ndarray:
        """(C,) int64 the rank of each corner's face among the faces of its edge (``corner_edge``), in face order."""
        order = np.argsort(self.corner_edge, kind="stable")
        first = np.zeros(self.n_edges + 1, dtype=np.int64)
        np.cumsum(self.edge_face_count, out=first[1:])
        rank = np.empty(len(order), dtype=np.int64)
        rank[order] = np.arange(len(order)) - first[self.corner_edge[order]]
        return rank

    @cached_property
    def edge_first_corner(self) -> np.ndarray:
        """(E,) int64 the corner (of the edge's first face) whose side is the edge."""
        first = np.empty(self.n_edges, dtype=np.int64)
        first[self.corner_edge[::-1]] = np.arange(len(self.corner_edge))[::-1]
        return first

    @cached_property
    def vertex_face_count(self) -> np.ndarray:
        """(V,) int64 faces around each vertex."""
        return np.bincount(self.corner_vertex, minlength=self.n_vertices)

    @cached_property
    def vertex_edge_count(self) -> np.ndarray:
        """(V,) int64 edges at each vertex."""
        return np.bincount(self.edge_vertices.ravel(), minlength=self.n_vertices)

    @cached_property
    def boundary_vertex(self) -> np.ndarray:
        """(V,) bool: the vertex lies on an edge with fewer than two faces."""
        on = np.zeros(self.n_vertices, dtype=bool)
        on[self.edge_vertices[self.edge_face_count < 2].ravel()] = True
        return on

    @cached_property
    def ring_position(self) -> np.ndarray:
        """(C,) int64 the position of each corner's face in its vertex's ring as Vtr orders it
        (Level::orderVertexFacesAndEdges): from the vertex's first face (a boundary vertex: the face whose
        side leaving the vertex is on the boundary), each next face across the side entering the vertex."""
        cv, n = self.corner_vertex, len(self.corner_vertex)
        V = np.int64(self.n_vertices)
        leaving = cv * V + cv[self.next]
        order = np.argsort(leaving, kind="stable")
        wanted = cv * V + cv[self.prev]
        found = np.minimum(np.searchsorted(leaving[order], wanted), n - 1)
        succ = np.where(leaving[order][found] == wanted, order[found], -1)
        start = np.full(self.n_vertices, n, dtype=np.int64)
        np.minimum.at(start, cv, np.arange(n))
        open_side = self.edge_face_count[self.corner_edge] < 2
        start[cv[open_side]] = np.flatnonzero(open_side)  # one leading boundary side per manifold vertex
        succ[succ == start[cv]] = -1  # the ring closes at its first face
        distance = (succ >= 0).astype(np.int64)  # to the ring's last face, by pointer doubling
        jump = succ.copy()
        while (jump >= 0).any():
            ahead = jump >= 0
            distance[ahead] += distance[jump[ahead]]
            jump[ahead] = jump[jump[ahead]]
        length = np.bincount(cv, minlength=self.n_vertices)
        return length[cv] - 1 - distance

    def vertex_sum(self, per_edge_end: np.ndarray, edges: np.ndarray | None = None) -> np.ndarray:
        """(V, K) float64: at each vertex, the sum over its edges (all, or those where ``edges`` (E,) bool)
        of the value at the edge's other end, ``per_edge_end`` (V, K) a value per vertex."""
        ends = self.edge_vertices if edges is None else self.edge_vertices[edges]
        return sum_by(np.concatenate([ends[:, 0], ends[:, 1]]),
                      np.concatenate([per_edge_end[ends[:, 1]], per_edge_end[ends[:, 0]]]), self.n_vertices)


def sum_by(index: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """(n, K) float64 sums of ``values`` (m, K) grouped by ``index`` (m,) int64 in [0, n)."""
    return np.stack([np.bincount(index, values[:, k], minlength=n) for k in range(values.shape[1])], axis=1) \
        if values.shape[1] else np.zeros((n, 0))
