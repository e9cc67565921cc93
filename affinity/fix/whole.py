"""Write a fixed mesh whole as ASCII PLY or OFF, formats whose vertices carry their attributes.

PLY and OFF keep normals (and, in OFF, texture coordinates) per vertex, where the mesh
model keeps them per corner: a vertex is written once per distinct combination of its
position and the per-corner values its corners use, so seams stay seams. PLY keeps
texture coordinates per corner in the face's ``texcoord`` list (the form the PLY reader
reads), OFF per vertex (``ST`` prefix). Colours are written as floats in [0, 1].
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh
from .layout import unique_rows


def _split_vertices(mesh: Mesh, per_vertex: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """One vertex per distinct (position, per-corner indices ``per_vertex``) of the corners.

    Returns
    -------
    first : (W,) int64 a corner of each written vertex, in the order of first use by position
    vertex_of : (C,) int64 the written vertex of every corner
    """
    columns = [mesh.corner_vertex] + [getattr(mesh, name) for name in per_vertex if getattr(mesh, name) is not None]
    first, vertex_of = unique_rows(np.stack(columns, axis=1))
    return first, vertex_of


def _rows(columns: list[np.ndarray]) -> list[str]:
    table = np.hstack([np.asarray(c, dtype=np.float64).reshape(len(c), -1) for c in columns])
    return [" ".join(map(repr, row)) for row in table.tolist()]


def _gathered(values: np.ndarray | None, index: np.ndarray | None, corners: np.ndarray, width: int) -> np.ndarray:
    """Values at ``corners`` through a per-corner index; zeros where a corner has none."""
    if values is None or index is None:
        return np.zeros((len(corners), width))
    picked = index[corners]
    return np.where((picked >= 0)[:, None], values[np.maximum(picked, 0)], 0.0)


def _face_lines(mesh: Mesh, vertex_of: np.ndarray, extra=None) -> list[str]:
    """``k i0 .. ik-1`` per face (written vertex indices), with ``extra`` (C, D) per-corner numbers after."""
    sizes = mesh.face_sizes
    lines = np.empty(mesh.n_faces, dtype=object)
    for size in np.unique(sizes).tolist():  # one pass per face size
        faces = np.flatnonzero(sizes == size)
        corners = mesh.face_start[faces, None] + np.arange(size)
        table = [np.full(len(faces), size), *vertex_of[corners].T]
        text = [" ".join(map(str, row)) for row in np.stack(table, axis=1).tolist()]
        if extra is not None:
            numbers = extra[corners].reshape(len(faces), -1)
            text = [f"{t} {2 * size} " + " ".join(map(repr, row)) for t, row in zip(text, numbers.tolist())]
        lines[faces] = text
    return lines.tolist()


def ply_text(mesh: Mesh, comment: str) -> str:
    """The mesh as ASCII PLY: vertex ``x y z [nx ny nz] [red green blue]``, face ``vertex_indices``
    and, when the mesh has texture coordinates, ``texcoord`` (u v per corner)."""
    first, vertex_of = _split_vertices(mesh, ["corner_normal"])
    columns = [mesh.positions[mesh.corner_vertex[first]]]
    header = ["ply", "format ascii 1.0", f"comment {comment}", f"element vertex {len(first)}",
              "property double x", "property double y", "property double z"]
    if mesh.normals is not None and mesh.corner_normal is not None:
        columns.append(_gathered(mesh.normals, mesh.corner_normal, first, 3))
        header += ["property double nx", "property double ny", "property double nz"]
    if mesh.colors is not None:
        columns.append(np.nan_to_num(mesh.colors[mesh.corner_vertex[first]]))
        header += ["property float red", "property float green", "property float blue"]
    uv = None
    header += [f"element face {mesh.n_faces}", "property list uchar int vertex_indices"]
    if mesh.texcoords is not None and mesh.corner_texcoord is not None:
        uv = _gathered(mesh.texcoords, mesh.corner_texcoord, np.arange(len(mesh.corner_vertex)), 2)
        header.append("property list uchar double texcoord")
    body = _rows(columns) + _face_lines(mesh, vertex_of, uv)
    return "\n".join([*header, "end_header", *body]) + "\n"


def off_text(mesh: Mesh, comment: str) -> str:
    """The mesh as OFF with the ``ST``, ``C`` and ``N`` prefixes its attributes need:
    vertex lines ``x y z [nx ny nz] [r g b] [s t]``."""
    first, vertex_of = _split_vertices(mesh, ["corner_texcoord", "corner_normal"])
    columns, prefix = [mesh.positions[mesh.corner_vertex[first]]], ""
    if mesh.normals is not None and mesh.corner_normal is not None:
        columns.append(_gathered(mesh.normals, mesh.corner_normal, first, 3))
        prefix = "N"
    if mesh.colors is not None:
        columns.append(np.nan_to_num(mesh.colors[mesh.corner_vertex[first]]))
        prefix = "C" + prefix
    if mesh.texcoords is not None and mesh.corner_texcoord is not None:
        columns.append(_gathered(mesh.texcoords, mesh.corner_texcoord, first, 2))
        prefix = "ST" + prefix
    lines = [f"{prefix}OFF", f"# {comment}", f"{len(first)} {mesh.n_faces} 0"]
    return "\n".join([*lines, *_rows(columns), *_face_lines(mesh, vertex_of)]) + "\n"
