"""Write a :class:`~affinity.mesh.Mesh` as Wavefront OBJ (faces kept as they are)."""

from __future__ import annotations

import io
import os

import numpy as np

from ..atomic import atomic_write
from ..mesh import Mesh


def _rows(keyword: str, values: np.ndarray) -> str:
    return "".join(f"{keyword} " + " ".join(f"{x:.17g}" for x in row) + "\n" for row in values.tolist())


def obj_text(mesh: Mesh, header: str | None = None) -> str:
    """The OBJ text: ``v`` (with ``r g b`` when the mesh has colours), ``vt``, ``vn``, ``g``, ``f``.

    Corner indices are written 1-based as ``v``, ``v/vt``, ``v//vn`` or ``v/vt/vn``
    depending on which per-corner indices the mesh has.
    """
    out = io.StringIO()
    if header:
        out.write(f"# {header}\n")
    vertices = mesh.positions if mesh.colors is None else np.hstack([mesh.positions, mesh.colors])
    out.write(_rows("v", vertices))
    if mesh.texcoords is not None:
        out.write(_rows("vt", mesh.texcoords))
    if mesh.normals is not None:
        out.write(_rows("vn", mesh.normals))

    def one_based(index):
        return None if index is None else (index + 1).tolist()

    v, vt, vn = one_based(mesh.corner_vertex), one_based(mesh.corner_texcoord), one_based(mesh.corner_normal)
    corners = [
        str(v[c]) + ("" if vt is None and vn is None else "/" + ("" if vt is None else str(vt[c])))
        + ("" if vn is None else "/" + str(vn[c]))
        for c in range(len(v))
    ]
    group = None
    for f, (start, stop) in enumerate(zip(mesh.face_start[:-1].tolist(), mesh.face_start[1:].tolist())):
        name = mesh.group_names[mesh.face_group[f]]
        if name and name != group:
            out.write(f"g {name}\n")
        group = name
        out.write("f " + " ".join(corners[start:stop]) + "\n")
    return out.getvalue()


def write_obj(mesh: Mesh, path: str | os.PathLike, header: str | None = None) -> None:
    """Write ``mesh`` to ``path`` as OBJ, atomically."""
    with atomic_write(path) as f:
        f.write(obj_text(mesh, header))
