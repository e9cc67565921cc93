"""A mesh's faces as sets: their corners' vertices, centroids, areas, normals, neighbours and sub-meshes.

Arrays of face indices in, arrays out; the close-ups (:mod:`.closeup`) frame and draw with them, and
flagged faces are grouped into places by them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..mesh import Mesh


def face_vertices(mesh: Mesh, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The corners' vertices of ``faces``: (C,) int64 vertex per corner and (C,) int64 its face (from ``faces``)."""
    sizes = mesh.face_sizes[faces]
    owner = np.repeat(faces, sizes)
    starts = np.repeat(mesh.face_start[faces], sizes)
    offsets = np.arange(len(owner)) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    return mesh.corner_vertex[starts + offsets], owner


def ring_of(mesh: Mesh, faces: np.ndarray) -> np.ndarray:
    """(N,) int64 sorted: ``faces`` and every face that shares a vertex with one of them."""
    touched = np.zeros(len(mesh.positions), dtype=bool)
    touched[face_vertices(mesh, faces)[0]] = True
    every_vertex, owner = face_vertices(mesh, np.arange(mesh.n_faces))
    return np.unique(np.concatenate([faces, owner[touched[every_vertex]]]))


def face_centroids(mesh: Mesh) -> np.ndarray:
    """(F, 3) float64: the mean of each face's corner positions."""
    if mesh.n_faces == 0:
        return np.zeros((0, 3))
    total = np.add.reduceat(mesh.positions[mesh.corner_vertex], mesh.face_start[:-1], axis=0)  # faces are not empty
    return total / mesh.face_sizes[:, None]


def vector_areas(mesh: Mesh, faces: np.ndarray) -> np.ndarray:
    """(F, 3) float64: twice each polygon's vector area (Newell: sum of p_k x p_k+1 over its corners)."""
    vertices, _ = face_vertices(mesh, faces)
    p = mesh.positions[vertices]
    sizes = mesh.face_sizes[faces]
    first = np.repeat(np.cumsum(sizes) - sizes, sizes)
    following = np.arange(len(p)) + 1
    following = np.where(following - first >= np.repeat(sizes, sizes), first, following)  # wrap within the face
    total = np.zeros((len(faces), 3))
    np.add.at(total, np.repeat(np.arange(len(faces)), sizes), np.cross(p, p[following]))
    return total


def mean_normal(mesh: Mesh, faces: np.ndarray) -> np.ndarray:
    """(3,) unit area-weighted normal of ``faces`` (Newell's vector area of each polygon), or +z if they cancel."""
    area = vector_areas(mesh, faces).sum(axis=0)
    length = np.linalg.norm(area)
    return area / length if length > 0 else np.array([0.0, 0.0, 1.0])


def face_subset(mesh: Mesh, faces: np.ndarray) -> Mesh:
    """A mesh of ``faces`` (D,) int64 sorted, in that order, with the same vertex and attribute tables.

    Positions, uv, normals and colours keep their indices (unused entries stay),
    so attributes, seams and scores are unchanged; face ``i`` of the result is
    face ``faces[i]`` of ``mesh``.
    """
    sizes = mesh.face_sizes[faces]
    corners = np.repeat(mesh.face_start[faces], sizes) + (np.arange(sizes.sum())
                                                           - np.repeat(np.cumsum(sizes) - sizes, sizes))

    def take(array):
        return None if array is None else array[corners]

    return replace(
        mesh, face_start=np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
        corner_vertex=mesh.corner_vertex[corners], face_line=mesh.face_line[faces],
        corner_texcoord=take(mesh.corner_texcoord), corner_normal=take(mesh.corner_normal),
        face_group=mesh.face_group[faces], face_material=mesh.face_material[faces], prim_face_start=None,
    )
