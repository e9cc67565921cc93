"""UV drift: how far subdivision moves the texture by itself. Under the smooth face-varying rules the limit
surface's uv is not the cage's bilinear uv: the texture slides over the surface even where every quad is a
parallelogram in uv. Measured at the corners of the level-``SAMPLE_LEVEL`` refinement of each face (a 5 x 5
grid on a quad), as the distance between the limit uv (``Scheme.fvar``) and the bilinear uv (the rule
``all``) there; the largest over the face."""

from __future__ import annotations

import numpy as np

from .refine import Scheme, refine_uniform

#: Levels of refinement whose corners sample a face: 2 puts a 5 x 5 grid on a quad (2^2 + 1 a side). On Spot
#: the largest drift of every quad lies on its level-1 points already (median and max equal at levels 1-3);
#: each level more costs four times the memory.
SAMPLE_LEVEL = 2


def uv_drift(face_start: np.ndarray, corner_vertex: np.ndarray, positions: np.ndarray, texcoords: np.ndarray,
             corner_texcoord: np.ndarray, scheme: Scheme, level: int = SAMPLE_LEVEL) -> np.ndarray:
    """(F, 2) float64 per face, the uv difference (limit minus bilinear) of largest length over its samples,
    in uv units; NaN rows for faces (and holes) with no sample, all NaN when a corner lacks uv.

    Parameters: the mesh's faces (F + 1,) int64, corners (C,) int64, positions (V, 3) float64, uv table
    (T, 2) float64 and each corner's uv (C,) int64; ``scheme`` its subdivision rules.
    """
    n_faces = len(face_start) - 1
    drift = np.full((n_faces, 2), np.nan)
    if corner_texcoord is None or (corner_texcoord < 0).any() or scheme.scheme != "catmullClark":
        return drift if scheme.scheme == "catmullClark" else np.zeros((n_faces, 2))
    channels = {"uv": (texcoords, corner_texcoord), "bilinear": (texcoords, corner_texcoord, "all")}
    limit = refine_uniform(face_start, corner_vertex, positions, level, scheme, channels, limit=True)
    values, index = limit.channels["uv"]
    bilinear, bilinear_index = limit.channels["bilinear"]  # the rule all: its limit is itself
    difference = values[index] - bilinear[bilinear_index]  # (4 R, 2), the refined corners in the same order
    length = np.hypot(difference[:, 0], difference[:, 1])
    drawn = np.repeat(~limit.hole, 4)
    face = np.repeat(limit.base_face, 4)[drawn]  # rising: a face's refined faces are contiguous (Far's order)
    difference, length = difference[drawn], length[drawn]
    if not len(face):
        return drift
    starts = np.flatnonzero(np.concatenate([[True], face[1:] != face[:-1]]))
    worst = np.maximum.reduceat(length, starts)
    at_worst = np.flatnonzero(length == np.repeat(worst, np.diff(np.append(starts, len(face)))))
    first = at_worst[np.concatenate([[True], face[at_worst][1:] != face[at_worst][:-1]])]
    drift[face[first]] = difference[first]
    return drift



def mesh_uv_drift(mesh, settings) -> np.ndarray:
    """(F, 2) float64 each face's UV drift (:func:`uv_drift`) where the mesh is drawn subdivided under
    ``settings`` (a level above 0 or the limit surface, Catmull-Clark), NaN rows elsewhere: USD prims by
    their own rules, other meshes by the ``fvar-interpolation`` setting."""
    from .pieces import drawn_levels, local_faces

    drift = np.full((mesh.n_faces, 2), np.nan)
    if mesh.texcoords is None:
        return drift
    face_scheme, schemes, levels = drawn_levels(mesh, settings)
    for s, (scheme, level) in enumerate(zip(schemes, levels)):
        if level == 0 or scheme.scheme != "catmullClark":
            continue
        faces = np.flatnonzero(face_scheme == s)
        local = local_faces(mesh, faces, scheme)
        uv = local.channel(mesh.texcoords, mesh.corner_texcoord)
        if uv is not None:
            drift[faces] = uv_drift(local.face_start, local.corner_vertex, local.positions, *uv, local.scheme)
    return drift
