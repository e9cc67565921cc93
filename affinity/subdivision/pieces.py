"""Which faces of a mesh a renderer draws subdivided, and at which level (the ``subdivision`` setting and
``profile``, :meth:`affinity.settings.Settings.subdivision_level`), and those faces in a numbering of their own
for refinement."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..mesh import Mesh
from .refine import Scheme


def drawn_levels(mesh: Mesh, settings) -> tuple[np.ndarray, list[Scheme], list]:
    """Per face, the index of its scheme (F,) int64; the schemes (a USD stage's per prim, else one: the
    ``fvar-interpolation`` setting on USD's fallbacks); and each scheme's drawn level (0, N or "limit")."""
    if mesh.subdivision is None:
        schemes = [Scheme(fvar=settings.fvar_interpolation)]
        return np.zeros(mesh.n_faces, dtype=np.int64), schemes, [settings.subdivision_level(False)]
    schemes = list(mesh.subdivision)
    levels = [settings.subdivision_level(True) if scheme.subdivides else 0 for scheme in schemes]
    return mesh.face_group.astype(np.int64), schemes, levels


@dataclass(frozen=True)
class LocalFaces:
    """Some faces of a mesh in a numbering of their own (what refinement takes): ``face_start`` (n + 1,),
    ``corner_vertex`` (C,) into ``positions`` (V', 3), the mesh's ``corners`` (C,) int64 they come from,
    the mesh's vertices ``used`` (V',) and the ``scheme`` with its creases, corners and holes renumbered."""

    face_start: np.ndarray
    corner_vertex: np.ndarray
    positions: np.ndarray
    corners: np.ndarray
    used: np.ndarray
    scheme: Scheme

    def channel(self, values: np.ndarray | None, index: np.ndarray | None) -> tuple | None:
        """A per-corner attribute of the mesh (``values`` (T, K), ``index`` (C_mesh,)) on these faces, its
        table cut to the values used; None where a corner lacks it."""
        if values is None or index is None or (index[self.corners] < 0).any():
            return None
        taken, value_index = np.unique(index[self.corners], return_inverse=True)
        return values[taken], value_index.ravel()


def local_faces(mesh: Mesh, faces: np.ndarray, scheme: Scheme) -> LocalFaces:
    """``faces`` (n,) int64 of ``mesh`` as :class:`LocalFaces` (vertices no face of theirs uses left out)."""
    starts, ends = mesh.face_start[faces], mesh.face_start[faces + 1]
    sizes = ends - starts
    corners = np.repeat(starts - np.concatenate([[0], np.cumsum(sizes)[:-1]]), sizes) + np.arange(sizes.sum())
    used, local = np.unique(mesh.corner_vertex[corners], return_inverse=True)
    remap = np.full(len(mesh.positions), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    creases = remap[scheme.crease_edges] if len(scheme.crease_edges) else scheme.crease_edges
    keep = (creases >= 0).all(axis=1) if len(creases) else np.zeros(0, dtype=bool)
    corner_vertices = remap[scheme.corner_vertices] if len(scheme.corner_vertices) else scheme.corner_vertices
    keep_corner = corner_vertices >= 0
    local_scheme = replace(scheme, crease_edges=creases[keep], crease_sharpness=scheme.crease_sharpness[keep],
                           corner_vertices=corner_vertices[keep_corner],
                           corner_sharpness=scheme.corner_sharpness[keep_corner],
                           holes=np.flatnonzero(np.isin(faces, scheme.holes)))
    return LocalFaces(np.concatenate([[0], np.cumsum(sizes)]), local.ravel(), mesh.positions[used], corners, used,
                      local_scheme)
