"""Uniform refinement of a polygon mesh to level L, as OpenSubdiv's Far::TopologyRefiner::RefineUniform and
PrimvarRefiner give it: level points (not projected to the limit), every face cut into one quad per corner
each level (triangles and n-gons become quads after the first level), each refined face remembering its
base face. The faces of level L come in Far's order: the children of face f are contiguous, child k starting
at corner k of f (a quad's children keep its orientation: child k has its parent vertex at its own corner k).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .catmark import refine_vertex_data, sharpen_boundaries, vertex_masks
from .facevarying import RULES, base_channel, limit_values, refine_channel
from .topology import Topology, decay

SCHEMES = ("catmullClark", "bilinear", "loop", "none")
BOUNDARY_RULES = ("none", "edgeOnly", "edgeAndCorner")


@dataclass(frozen=True)
class Scheme:
    """How a mesh subdivides (USD's UsdGeomMesh attributes, OpenSubdiv's Sdc options).

    Attributes
    ----------
    scheme : one of :data:`SCHEMES` (``none``: the mesh is drawn as its cage)
    boundary : one of :data:`BOUNDARY_RULES` (``interpolateBoundary``)
    fvar : one of :data:`facevarying.RULES` (``faceVaryingLinearInterpolation``)
    crease_edges : (k, 2) int64 vertex pairs; crease_sharpness : (k,) float64
    corner_vertices : (m,) int64; corner_sharpness : (m,) float64
    holes : (h,) int64 faces not drawn
    """

    scheme: str = "catmullClark"
    boundary: str = "edgeAndCorner"
    fvar: str = "cornersPlus1"
    crease_edges: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    crease_sharpness: np.ndarray = field(default_factory=lambda: np.zeros(0))
    corner_vertices: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    corner_sharpness: np.ndarray = field(default_factory=lambda: np.zeros(0))
    holes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def __post_init__(self):
        for value, allowed in ((self.scheme, SCHEMES), (self.boundary, BOUNDARY_RULES), (self.fvar, RULES)):
            if value not in allowed:
                raise ValueError(f"{value!r} is not one of {', '.join(allowed)}")

    @property
    def subdivides(self) -> bool:
        return self.scheme != "none"


@dataclass(frozen=True)
class Refined:
    """A mesh refined to ``level``.

    Attributes
    ----------
    positions : (V, 3) float64
    face_start : (F + 1,) int64, corner_vertex : (C,) int64 (every face a quad from level 1 on)
    base_face : (F,) int64 the base face each refined face lies in
    hole : (F,) bool
    channels : dict of name -> ((T, K) float64 values, (C,) int64 value of each corner)
    vertex_data : dict of name -> (V, K) float64 (data refined with the positions' masks, e.g. vertex colours)
    """

    level: int
    positions: np.ndarray
    face_start: np.ndarray
    corner_vertex: np.ndarray
    base_face: np.ndarray
    hole: np.ndarray
    channels: dict
    vertex_data: dict


def _edge_lookup(topology: Topology, pairs: np.ndarray) -> np.ndarray:
    """(k,) int64 the edge of each vertex pair (k, 2), -1 where the pair is no edge of the mesh."""
    keys = np.minimum(pairs[:, 0], pairs[:, 1]) * np.int64(topology.n_vertices) + np.maximum(pairs[:, 0], pairs[:, 1])
    edge_keys = topology.edge_vertices[:, 0] * np.int64(topology.n_vertices) + topology.edge_vertices[:, 1]
    found = np.minimum(np.searchsorted(edge_keys, keys), max(len(edge_keys) - 1, 0))
    return np.where((len(edge_keys) > 0) & (edge_keys[found] == keys), found, -1)


def _child_topology(topology: Topology) -> tuple[Topology, np.ndarray]:
    """The next level's faces (one quad per corner, Far's order and orientation) and the (C, 4) slot order
    used to place the quad's corners: slot j of child c goes to corner (j + shift[c]) % 4."""
    F, E = topology.n_faces, topology.n_edges
    c = np.arange(len(topology.corner_vertex))
    slots = np.stack([F + E + topology.corner_vertex, F + topology.corner_edge, topology.corner_face,
                      F + topology.corner_edge[topology.prev]], axis=1)
    shift = np.where(topology.face_size[topology.corner_face] == 4, topology.corner_local, 0)
    order = (np.arange(4)[None, :] + shift[:, None]) % 4
    corners = np.empty_like(slots)
    np.put_along_axis(corners, order, slots, axis=1)
    child = Topology(4 * np.arange(len(c) + 1, dtype=np.int64), corners.ravel(), F + E + topology.n_vertices)
    # Child edges: the two halves of each parent edge (2e to its lower vertex, 2e + 1 to its higher one), then
    # one inside each face per parent corner (2E + c, from the face point to the corner's next edge point).
    ends = topology.edge_vertices
    halves = np.stack([np.repeat(F + np.arange(E), 2), F + E + ends.ravel()], axis=1)
    inner = np.stack([topology.corner_face, F + topology.corner_edge], axis=1)
    v = topology.corner_vertex
    next_half = 2 * topology.corner_edge + (ends[topology.corner_edge, 1] == v)
    prev_edge = topology.corner_edge[topology.prev]
    prev_half = 2 * prev_edge + (ends[prev_edge, 1] == v)
    sides = np.stack([next_half, 2 * E + c, 2 * E + topology.prev, prev_half], axis=1)
    corner_edge = np.empty_like(sides)
    np.put_along_axis(corner_edge, order, sides, axis=1)
    return child.given_edges(np.concatenate([halves, inner]), corner_edge.ravel()), order


def refine_uniform(face_start: np.ndarray, corner_vertex: np.ndarray, positions: np.ndarray, level: int,
                   scheme: Scheme = Scheme(), channels: dict | None = None,
                   vertex_data: dict | None = None, limit: bool = False) -> Refined:
    """Refine a mesh uniformly ``level`` times.

    Parameters
    ----------
    face_start : (F + 1,) int64; corner_vertex : (C,) int64; positions : (V, 3) float64
    level : int >= 0
    scheme : :class:`Scheme` (catmullClark or bilinear; loop is not refined here)
    channels : dict of name -> ((T, K) float64 values, (C,) int64 value index per corner[, rule]), face-varying
        data refined under ``scheme.fvar`` or the rule given (uv, per-corner normals)
    vertex_data : dict of name -> (V, K) float64, per-vertex data refined as the positions are
    limit : the channels' values projected to the limit surface at level ``level`` (>= 1; positions stay
        level points): the limit uv at each refined corner
    """
    if scheme.scheme == "loop":
        raise ValueError("Loop subdivision is not refined here")
    channels, vertex_data = channels or {}, vertex_data or {}
    topology = Topology(np.asarray(face_start, dtype=np.int64), np.asarray(corner_vertex, dtype=np.int64),
                        len(positions))
    base_face = np.arange(topology.n_faces)
    edge_sharpness = np.zeros(topology.n_edges)
    crease = _edge_lookup(topology, np.asarray(scheme.crease_edges, dtype=np.int64).reshape(-1, 2))
    np.maximum.at(edge_sharpness, crease[crease >= 0], np.asarray(scheme.crease_sharpness, float)[crease >= 0])
    vertex_sharpness = np.zeros(topology.n_vertices)
    np.maximum.at(vertex_sharpness, np.asarray(scheme.corner_vertices, dtype=np.int64),
                  np.asarray(scheme.corner_sharpness, dtype=np.float64))
    edge_sharpness, vertex_sharpness, hole = sharpen_boundaries(topology, edge_sharpness, vertex_sharpness,
                                                                scheme.boundary)
    if scheme.scheme == "bilinear":  # a bilinear face needs no neighbours: boundary faces stay (Far)
        hole[:] = False
    hole[np.asarray(scheme.holes, dtype=np.int64)] = True
    data = {"positions": np.asarray(positions, dtype=np.float64),
            **{name: np.asarray(values, dtype=np.float64) for name, values in vertex_data.items()}}
    fvar = {name: base_channel(topology, channel[0], np.asarray(channel[1], dtype=np.int64),
                               "all" if scheme.scheme == "bilinear" else (channel[2:] or (scheme.fvar,))[0],
                               edge_sharpness, vertex_sharpness, scheme.boundary)
            for name, channel in channels.items()}
    for _ in range(level):
        masks = vertex_masks(topology, edge_sharpness, vertex_sharpness) if scheme.scheme != "bilinear" else None
        data = {name: refine_vertex_data(topology, masks, edge_sharpness, values) for name, values in data.items()}
        child, order = _child_topology(topology)
        F, E = topology.n_faces, topology.n_edges
        child_edge_parent = np.concatenate([np.repeat(np.arange(E), 2), np.full(child.n_edges - 2 * E, -1)])
        refined = {}
        for name, channel in fvar.items():
            channel, slots = refine_channel(topology, channel, masks, edge_sharpness, vertex_sharpness,
                                            child_edge_parent)
            corner_value = np.empty_like(slots)
            np.put_along_axis(corner_value, order, slots, axis=1)
            refined[name] = _with_corners(channel, corner_value.ravel())
        fvar = refined
        edge_sharpness = np.where(child_edge_parent >= 0, decay(edge_sharpness)[np.maximum(child_edge_parent, 0)], 0.0)
        vertex_sharpness = np.concatenate([np.zeros(F + E), decay(vertex_sharpness)])
        base_face = base_face[topology.corner_face]
        hole = hole[topology.corner_face]
        topology = child
    if limit:
        fvar = {name: _with_values(channel, limit_values(topology, channel, edge_sharpness, vertex_sharpness))
                for name, channel in fvar.items()}
    return Refined(level=level, positions=data.pop("positions"), face_start=topology.face_start,
                   corner_vertex=topology.corner_vertex, base_face=base_face, hole=hole,
                   channels={name: (channel.values, channel.corner_value) for name, channel in fvar.items()},
                   vertex_data=data)


def _with_corners(channel, corner_value: np.ndarray):
    return replace(channel, corner_value=corner_value)


def _with_values(channel, values: np.ndarray):
    return replace(channel, values=values)
