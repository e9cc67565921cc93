"""Build the fixed mesh: refined quads, transition faces, and every other face as it was.

Each attribute table (positions with their vertex colours, texture coordinates,
normals) grows by the values of its new entries, appended after the existing ones so
no index of the input moves:

* points on edges, one run per distinct (start, end, count) of table indices, at the
  edge's parameters (k / count, :mod:`affinity.fix.layout`) along the edge in its canonical
  direction (so both faces on an edge get bit-identical values) — the bilinear blend
  restricted to the edge;
* the inner points of each cut face (:mod:`affinity.fix.patterns`), the bilinear blend of its
  corners at their (s, t) (:mod:`affinity.fix.grid`).

Normals are scaled back to unit length after blending. A corner without a value
(index -1) gives its new points none either.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..mesh import Mesh
from .grid import weights_at
from .layout import Layout, edge_parameters, face_patterns, layout, unique_rows
from .patterns import face_pattern


@dataclass(eq=False)
class Refined:
    """The fixed mesh and how its faces relate to the input's.

    Attributes
    ----------
    mesh : the fixed mesh; its first V, T, N positions, texture coordinates and normals are the input's
    source : (F',) int64 the input face each face of ``mesh`` is, or replaces
    added : (F',) bool the face is new (a piece of a refined quad or of a transition face)
    replaced : (k,) int64 input faces no longer in ``mesh``, ascending
    """

    mesh: Mesh
    source: np.ndarray
    added: np.ndarray
    replaced: np.ndarray


class _Table:
    """One attribute table growing by appended entries: ``values`` (N, D) float64, ``index`` (C,) int64."""

    def __init__(self, values: np.ndarray, index: np.ndarray, unit: bool):
        self.values, self.index, self.unit = values, index, unit
        self.parts = [values]
        self.size = len(values)

    def append(self, values: np.ndarray) -> np.ndarray:
        """Append (k, D) values; returns their (k,) int64 indices."""
        if self.unit:
            length = np.linalg.norm(values, axis=1, keepdims=True)
            values = np.divide(values, length, out=values.copy(), where=length > 0)
        self.parts.append(values)
        self.size += len(values)
        return np.arange(self.size - len(values), self.size)

    def blend_new(self, corner_index: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """New entries blending the values at ``corner_index`` (Q, k) with ``weights`` (P, k):
        (Q, P) int64 indices, -1 where a corner has no value."""
        missing = (corner_index < 0).any(axis=1)
        ids = np.full((len(corner_index), len(weights)), -1, dtype=np.int64)
        good = np.flatnonzero(~missing)
        if len(good):
            blended = np.einsum("pk,qkd->qpd", weights, self.values[corner_index[good]])
            ids[good] = self.append(blended.reshape(-1, self.values.shape[1])).reshape(len(good), -1)
        return ids

    def done(self) -> np.ndarray:
        return np.concatenate(self.parts)


def _edge_points(table: _Table, placed: Layout) -> tuple[np.ndarray, np.ndarray]:
    """New entries on every edge with points, in ``table``; per corner, the points of the edge that leaves it.

    Returns
    -------
    start : (C + 1,) int64 corner c's points are ``points[start[c]:start[c + 1]]``
        (:func:`affinity.fix.layout.edge_parameters` of its edge's count), in the direction of its face
    points : (S,) int64 indices into the table, -1 where an end of the edge has no value
    """
    per_corner = placed.points
    start = np.concatenate([[0], np.cumsum(per_corner)])
    points = np.full(start[-1], -1, dtype=np.int64)
    split = np.flatnonzero(per_corner > 0)
    a, b, count = table.index[split], table.index[placed.following[split]], placed.counts[split]
    forward = (placed.start[split] < placed.end[split]) | ((placed.start[split] == placed.end[split]) & (a <= b))
    low, high = np.where(forward, a, b), np.where(forward, b, a)
    valued = (a >= 0) & (b >= 0)
    ends = np.stack([low, high, count], axis=1)[valued]
    first_row, which = unique_rows(ends)
    keys = ends[first_row]
    first = np.zeros(len(keys), dtype=np.int64)
    for count in np.unique(keys[:, 2]).tolist():  # one pass per count of segments on an edge
        rows = np.flatnonzero(keys[:, 2] == count)
        t = edge_parameters(count)[None, :, None]
        lerped = table.values[keys[rows, 0]][:, None] * (1 - t) + table.values[keys[rows, 1]][:, None] * t
        first[rows] = table.append(lerped.reshape(-1, table.values.shape[1]))[:: t.shape[1]]
    occurrence = np.flatnonzero(valued)
    count = per_corner[split[occurrence]]
    j = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    along = np.where(np.repeat(forward[occurrence], count), j, np.repeat(count, count) - 1 - j)
    points[np.repeat(start[split[occurrence]], count) + j] = np.repeat(first[which], count) + along
    return start, points


class _Faces:
    """New faces collected in chunks of one size: their input face and their corners in every table."""

    def __init__(self, names):
        self.names = names
        self.chunks: list[tuple[np.ndarray, dict[str, np.ndarray]]] = []

    def add(self, source: np.ndarray, corners: dict[str, np.ndarray]) -> None:
        """``source`` (A,) int64 and per table (A, k) int64 corner indices."""
        if len(source):
            self.chunks.append((source, corners))

    def csr(self) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
        """source (A,), sizes (A,), flat corners per table, the faces ordered by source (stable)."""
        if not self.chunks:
            return np.zeros(0, np.int64), np.zeros(0, np.int64), {name: np.zeros(0, np.int64) for name in self.names}
        source = np.concatenate([s for s, _ in self.chunks])
        sizes = np.concatenate([np.full(len(s), c[self.names[0]].shape[1]) for s, c in self.chunks])
        flat = {name: np.concatenate([c[name].reshape(-1) for _, c in self.chunks]) for name in self.names}
        order = np.argsort(source, kind="stable")
        return source[order], sizes[order], {name: values[corner_slots(sizes, order)] for name, values in flat.items()}


def corner_slots(sizes: np.ndarray, order: np.ndarray) -> np.ndarray:
    """(sum sizes[order],) int64 flat positions of the corners of faces ``order`` (k,) int64, in that
    order, in a face table whose faces have ``sizes`` (F,) corners."""
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    picked = sizes[order]
    return np.repeat(starts[order], picked) + np.arange(picked.sum()) - np.repeat(np.cumsum(picked) - picked, picked)


def refine_mesh(mesh: Mesh, plan) -> Refined:
    """Apply ``plan`` (a :class:`affinity.fix.plan.FixPlan`) to ``mesh`` (module docstring): the fixed mesh and
    where its faces came from."""
    if plan.refined is not None:
        return plan.refined
    return build(mesh, layout(mesh, plan.refine_faces, plan.refine_n, plan.frozen_faces))


def build(mesh: Mesh, placed: Layout) -> Refined:
    """The fixed mesh of the refinement ``placed``: the refined quads and the faces beside them cut, the rest kept."""
    positions = mesh.positions if mesh.colors is None else np.hstack([mesh.positions, mesh.colors])
    tables = {"positions": _Table(positions, mesh.corner_vertex, unit=False)}
    if mesh.texcoords is not None and mesh.corner_texcoord is not None:
        tables["texcoords"] = _Table(mesh.texcoords, mesh.corner_texcoord, unit=False)
    if mesh.normals is not None and mesh.corner_normal is not None:
        tables["normals"] = _Table(mesh.normals, mesh.corner_normal, unit=True)
    edges = {name: _edge_points(table, placed) for name, table in tables.items()}
    faces = _Faces(list(tables))
    replaced = np.union1d(np.flatnonzero(placed.level), placed.transition_faces)
    for (counts, level), chosen in face_patterns(mesh, placed, replaced):
        pattern = face_pattern(counts, level)
        ids = {name: _local_points(table, edges[name], mesh, chosen, counts, pattern.inner)
               for name, table in tables.items()}
        for size in sorted({len(p) for p in pattern.polygons}):
            picked = np.array([p for p in pattern.polygons if len(p) == size])
            faces.add(np.repeat(chosen, len(picked)),
                      {name: local[:, picked].reshape(-1, size) for name, local in ids.items()})
    return _assemble(mesh, replaced, tables, faces)


def _local_points(table: _Table, edge: tuple, mesh: Mesh, faces: np.ndarray, counts: tuple,
                  inner: np.ndarray) -> np.ndarray:
    """(T, L) int64 table indices of the local ids of a :class:`~affinity.fix.patterns.Pattern` for the faces
    ``faces`` (T,) of one pattern: the ring (corners, edge points), then the ``inner`` (K, 2) points, each the
    bilinear blend of the face's four corners at its (s, t)."""
    start, points = edge
    corners = mesh.face_start[faces, None] + np.arange(len(counts))
    columns = []
    for i, count in enumerate(counts):
        columns += [table.index[corners[:, i, None]], points[start[corners[:, i], None] + np.arange(count - 1)]]
    if len(inner):
        columns.append(table.blend_new(table.index[corners], weights_at(inner)))
    return np.concatenate(columns, axis=1)


def _assemble(mesh: Mesh, replaced: np.ndarray, tables: dict, faces: _Faces) -> Refined:
    """The fixed mesh: kept faces in file order, then the new faces by the face they replace
    (within each USD prim, so the prims' faces stay contiguous)."""
    kept = np.setdiff1d(np.arange(mesh.n_faces), replaced)
    source_new, sizes_new, corners_new = faces.csr()
    source = np.concatenate([kept, source_new])
    added = np.concatenate([np.zeros(len(kept), bool), np.ones(len(source_new), bool)])
    prim = np.zeros(mesh.n_faces, dtype=np.int64)
    if mesh.prim_face_start is not None:
        prim = np.repeat(np.arange(len(mesh.prim_face_start) - 1), np.diff(mesh.prim_face_start))
    order = np.lexsort((np.arange(len(source)), added, prim[source]))
    sizes = np.concatenate([mesh.face_sizes[kept], sizes_new])
    kept_corners = corner_slots(mesh.face_sizes, kept)
    corner_of = {name: np.concatenate([table.index[kept_corners], corners_new[name]])[corner_slots(sizes, order)]
                 for name, table in tables.items()}
    source, added, sizes = source[order], added[order], sizes[order]
    vertex_values = tables["positions"].done()
    fixed = replace(
        mesh,
        positions=np.ascontiguousarray(vertex_values[:, :3]),
        colors=None if mesh.colors is None else np.clip(vertex_values[:, 3:], 0.0, 1.0),  # blends round past 1
        face_start=np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
        corner_vertex=corner_of["positions"],
        face_line=np.where(added, 0, mesh.face_line[source]).astype(np.int64),
        texcoords=tables["texcoords"].done() if "texcoords" in tables else mesh.texcoords,
        corner_texcoord=corner_of.get("texcoords"),
        normals=tables["normals"].done() if "normals" in tables else mesh.normals,
        corner_normal=corner_of.get("normals"),
        face_group=mesh.face_group[source],
        face_material=mesh.face_material[source],
        prim_face_start=None if mesh.prim_face_start is None else np.concatenate(
            [[0], np.cumsum(np.bincount(prim[source], minlength=len(mesh.prim_face_start) - 1))]).astype(np.int64),
        notes=list(mesh.notes),
    )
    return Refined(fixed, source, added, replaced)


def apply_fix(mesh: Mesh, plan) -> Mesh:
    """The fixed mesh of ``plan`` (:func:`refine_mesh` without the bookkeeping)."""
    return refine_mesh(mesh, plan).mesh
