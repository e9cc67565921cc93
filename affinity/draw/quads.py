"""A mesh as the renderer's quads.

``render`` takes quads only (design.md): quads pass as they are, triangles as
quads with a repeated last corner, n-gons are fanned into triangles here.
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh


def render_corners(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """The mesh as renderable quads.

    Returns
    -------
    faces : (R,) int64
        The mesh face each render quad comes from.
    corners : (R, 4) int64
        Corner indices; a triangle repeats its last corner, an n-gon becomes
        the fan (0, i, i+1, i+1) of triangles.
    """
    faces, corners = [], []
    for size in np.unique(mesh.face_sizes).tolist():
        of_size, face_corners = mesh.faces_of_size(size)
        if size == 4:
            quads = face_corners
            owners = of_size
        else:
            fan = np.arange(1, size - 1)
            quads = np.stack(
                [np.repeat(face_corners[:, :1], len(fan), 1), face_corners[:, fan],
                 face_corners[:, fan + 1], face_corners[:, fan + 1]], axis=-1,
            ).reshape(-1, 4)
            owners = np.repeat(of_size, len(fan))
        faces.append(owners)
        corners.append(quads)
    if not faces:
        return np.zeros(0, np.int64), np.zeros((0, 4), np.int64)
    faces, corners = np.concatenate(faces), np.concatenate(corners)
    order = np.argsort(faces, kind="stable")
    return faces[order], corners[order]
