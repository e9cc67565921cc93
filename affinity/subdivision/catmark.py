"""Catmull-Clark (and bilinear) refinement of vertex data by one level, with creases: the masks of
OpenSubdiv's Sdc (Catmull & Clark 1978; semi-sharp creases after DeRose, Kass & Truong 1998, sec. 3,
with the uniform creasing rule and the fractional blend where a feature's sharpness runs out).

A mask is kept as per-element coefficients on a few sums, so one set of coefficients serves the
positions and every face-varying channel whose topology matches the vertices' there:

- a vertex point is ``x * w_self + S_edges * w_edges + S_faces * w_faces + S_sharp * w_sharp
  + S_child_sharp * w_child_sharp``: ``x`` the vertex's value, ``S_edges`` the sum over its edges of
  the other end's value, ``S_faces`` the sum of the face points around it, ``S_sharp`` the other ends of
  its sharp edges (sharpness > 0) and ``S_child_sharp`` those of the edges still sharp a level down;
- an edge point is ``(a + b) * w_ends + (F_0 + F_1) * w_faces`` for ends a, b and face points F.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .topology import INFINITE, Topology, decay, sum_by

SMOOTH, DART, CREASE, CORNER = 0, 1, 2, 3


def vertex_rule(vertex_sharpness: np.ndarray, sharp_edges: np.ndarray) -> np.ndarray:
    """(V,) int8 Sdc vertex rule from the vertex's sharpness (V,) and its count of sharp edges (V,):
    a sharp vertex or more than two sharp edges: CORNER; two: CREASE; one: DART; none: SMOOTH."""
    rule = np.minimum(sharp_edges, 3).astype(np.int8)
    rule[vertex_sharpness > 0] = CORNER
    return rule


def fractional_weight(parent_sharpness: np.ndarray, index: np.ndarray, n: int) -> np.ndarray:
    """(n,) float64 Sdc::Crease::ComputeFractionalWeightAtVertex: the mean parent sharpness of the features
    (``parent_sharpness`` (m,), grouped by ``index`` (m,) into n) that go from sharp to smooth a level
    down, at most 1; 0 where none does."""
    transits = (parent_sharpness > 0) & (decay(parent_sharpness) <= 0)
    total = np.bincount(index[transits], parent_sharpness[transits], minlength=n)
    count = np.bincount(index[transits], minlength=n)
    return np.minimum(np.divide(total, count, out=np.zeros(n), where=count > 0), 1.0)


@dataclass(frozen=True)
class VertexMasks:
    """Coefficients (each (V,) float64) of the vertex-point sums (module docstring), and the edges whose
    other ends ``S_sharp`` and ``S_child_sharp`` sum: ``sharp`` and ``child_sharp`` (E,) bool."""

    self_: np.ndarray
    edges: np.ndarray
    faces: np.ndarray
    sharp: np.ndarray
    child_sharp: np.ndarray
    sharp_edges: np.ndarray
    child_sharp_edges: np.ndarray

    def apply(self, x, s_edges, s_faces, s_sharp, s_child_sharp) -> np.ndarray:
        """(n, K) vertex points from the sums, each (n, K), of the n vertices these masks are taken at."""
        return (x * self.self_[:, None] + s_edges * self.edges[:, None] + s_faces * self.faces[:, None]
                + s_sharp * self.sharp[:, None] + s_child_sharp * self.child_sharp[:, None])


def vertex_masks(topology: Topology, edge_sharpness: np.ndarray, vertex_sharpness: np.ndarray) -> VertexMasks:
    """Sdc::Scheme<CATMARK>::ComputeVertexVertexMask for every vertex: the parent rule's mask, blended with
    the child rule's by the fractional weight where the two differ."""
    V = topology.n_vertices
    ends = topology.edge_vertices.ravel()
    sharp = edge_sharpness > 0
    child_sharp = decay(edge_sharpness) > 0
    parent_rule = vertex_rule(vertex_sharpness, np.bincount(ends, np.repeat(sharp, 2), minlength=V).astype(int))
    child_rule = vertex_rule(decay(vertex_sharpness),
                             np.bincount(ends, np.repeat(child_sharp, 2), minlength=V).astype(int))
    n = topology.vertex_face_count.astype(np.float64)
    n[n == 0] = 1.0

    def mask(rule):
        """(self, edges, faces, crease ends) coefficients of one rule per vertex."""
        smooth = rule <= DART
        crease = rule == CREASE
        self_ = np.where(smooth, (n - 2) / n, np.where(crease, 0.75, 1.0))
        spoke = np.where(smooth, 1 / (n * n), 0.0)
        return self_, spoke, spoke, np.where(crease, 0.125, 0.0)

    p_self, p_edges, p_faces, p_sharp = mask(parent_rule)
    c_self, c_edges, c_faces, c_sharp = mask(child_rule)
    weight = fractional_weight(np.concatenate([vertex_sharpness, np.repeat(edge_sharpness, 2)]),
                               np.concatenate([np.arange(V), ends]), V)
    blend = (parent_rule > DART) & (child_rule != parent_rule)
    w = np.where(blend, weight, 1.0)  # the parent mask's share
    return VertexMasks(self_=w * p_self + (1 - w) * np.where(blend, c_self, 0.0),
                       edges=w * p_edges + (1 - w) * np.where(blend, c_edges, 0.0),
                       faces=w * p_faces + (1 - w) * np.where(blend, c_faces, 0.0),
                       sharp=w * p_sharp, child_sharp=(1 - w) * np.where(blend, c_sharp, 0.0),
                       sharp_edges=sharp, child_sharp_edges=child_sharp)


def edge_masks(edge_sharpness: np.ndarray, face_count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(E,) float64 coefficients ``w_ends`` and ``w_faces`` of every edge point (Sdc ComputeEdgeVertexMask):
    smooth 1/4 and 1/4, crease 1/2 and 0, a crease whose sharpness s < 1 runs out at this level s of the
    crease and 1 - s of the smooth mask. Edges without exactly two faces are creases (they are sharp)."""
    s = np.where(face_count == 2, np.minimum(edge_sharpness, 1.0), 1.0)
    return 0.25 + 0.25 * s, 0.25 * (1 - s)


def face_points(topology: Topology, corner_values: np.ndarray) -> np.ndarray:
    """(F, K) float64 the mean of each face's corner values ``corner_values`` (C, K)."""
    return np.add.reduceat(corner_values, topology.face_start[:-1], axis=0) / topology.face_size[:, None]


def refine_vertex_data(topology: Topology, masks: VertexMasks | None, edge_sharpness: np.ndarray,
                       values: np.ndarray) -> np.ndarray:
    """(F + E + V, K) float64 one level of vertex data ``values`` (V, K): face points, edge points, vertex
    points, in that order (the child level's vertices). ``masks`` None: the bilinear scheme (edge midpoints,
    vertices kept)."""
    faces = face_points(topology, values[topology.corner_vertex])
    a, b = values[topology.edge_vertices[:, 0]], values[topology.edge_vertices[:, 1]]
    if masks is None:
        return np.concatenate([faces, (a + b) / 2, values])
    w_ends, w_faces = edge_masks(edge_sharpness, topology.edge_face_count)
    face_sum = sum_by(topology.corner_edge, faces[topology.corner_face], topology.n_edges)
    edges = (a + b) * w_ends[:, None] + face_sum * w_faces[:, None]
    s_faces = sum_by(topology.corner_vertex, faces[topology.corner_face], topology.n_vertices)
    vertices = masks.apply(values, topology.vertex_sum(values), s_faces,
                           topology.vertex_sum(values, masks.sharp_edges),
                           topology.vertex_sum(values, masks.child_sharp_edges))
    return np.concatenate([faces, edges, vertices])


def sharpen_boundaries(topology: Topology, edge_sharpness: np.ndarray, vertex_sharpness: np.ndarray,
                       boundary: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The base level's sharpness with the boundary rule applied (Far's prepareComponentTagsAndSharpness):
    boundary and non-manifold edges infinitely sharp; under ``edgeAndCorner`` a vertex with one face and two
    edges too. Returns edge sharpness (E,), vertex sharpness (V,) and (F,) bool the faces that become holes
    under ``none`` (those at a boundary vertex with a boundary edge not already infinitely sharp)."""
    open_edge = topology.edge_face_count < 2
    holes = np.zeros(topology.n_faces, dtype=bool)
    if boundary == "none":
        excluding = np.zeros(topology.n_vertices, dtype=bool)
        excluding[topology.edge_vertices[open_edge & (edge_sharpness < INFINITE)].ravel()] = True
        holes = np.bincount(topology.corner_face, excluding[topology.corner_vertex],
                            minlength=topology.n_faces) > 0
    edge_sharpness = np.where(open_edge | (topology.edge_face_count > 2), INFINITE, edge_sharpness)
    vertex_sharpness = vertex_sharpness.copy()
    if boundary == "edgeAndCorner":
        corner = (topology.vertex_face_count == 1) & (topology.vertex_edge_count == 2)
        vertex_sharpness[corner] = INFINITE
    return edge_sharpness, vertex_sharpness, holes
