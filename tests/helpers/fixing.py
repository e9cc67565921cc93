"""Meshes and checks the fix's tests share: a grid with one flagged quad, a textured copy, and the edge map that
finds T-junctions (tests/test_fix.py, tests/test_fix_quads.py, tests/test_fix_cli.py)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from affinity.mesh import Mesh, mesh_from_polygons


def grid_with_one_flagged_quad(size: int = 5) -> tuple[Mesh, int]:
    """A flat size x size grid whose uv is the positions scaled, but the middle quad carries a
    trapezoid of uv of its own (a uv seam around it): only that quad is flagged."""
    xs = np.arange(size + 1, dtype=float)
    X, Y = np.meshgrid(xs, xs)
    positions = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)
    faces = np.array([[j * (size + 1) + i, j * (size + 1) + i + 1, (j + 1) * (size + 1) + i + 1,
                       (j + 1) * (size + 1) + i] for j in range(size) for i in range(size)])
    middle = (size // 2) * size + size // 2
    mesh = mesh_from_polygons("grid", positions, faces, texcoords=positions[:, :2] / size)
    texcoords = np.vstack([mesh.texcoords, [[0.40, 0.40], [0.60, 0.40], [0.57, 0.6], [0.43, 0.6]]])
    corner_texcoord = mesh.corner_texcoord.copy()
    corner_texcoord[4 * middle : 4 * middle + 4] = len(mesh.texcoords) + np.arange(4)
    mesh.texcoords, mesh.corner_texcoord = texcoords, corner_texcoord
    return mesh, middle


def edges_by_multiplicity(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Undirected edges between distinct positions: ends (E, 2) welded ids, faces sharing each (E,),
    and the positions (E, 2, 3)."""
    ids = welded(mesh)[mesh.corner_vertex]
    following = np.arange(len(ids)) + 1
    face_of = np.repeat(np.arange(mesh.n_faces), mesh.face_sizes)
    last = following == mesh.face_start[face_of + 1]
    following[last] = mesh.face_start[face_of[last]]
    pairs = np.sort(np.stack([ids, ids[following]], axis=1), axis=1)
    ends_at = np.stack([mesh.corner_vertex, mesh.corner_vertex[following]], axis=1)
    keep = pairs[:, 0] != pairs[:, 1]
    edges, first, count = np.unique(pairs[keep], axis=0, return_index=True, return_counts=True)
    return edges, count, mesh.positions[ends_at[keep][first]]


def edge_map_agrees(before: Mesh, after: Mesh) -> None:
    """No T-junction: for every number of faces k other than 2, the output's edges shared by k faces
    cover exactly the input's (same total length, each lying on an input edge of the same k); edges
    inside an input face are shared by 2."""
    _, count_in, ends_in = edges_by_multiplicity(before)
    _, count_out, ends_out = edges_by_multiplicity(after)
    length_in = np.linalg.norm(ends_in[:, 1] - ends_in[:, 0], axis=1)
    length_out = np.linalg.norm(ends_out[:, 1] - ends_out[:, 0], axis=1)
    for k in sorted(set(count_in.tolist()) | set(count_out.tolist()) - {2}):
        if k == 2:
            continue
        assert length_out[count_out == k].sum() == pytest.approx(length_in[count_in == k].sum(), rel=1e-9), k
        a, b = ends_in[count_in == k, 0], ends_in[count_in == k, 1]
        for p, q in ends_out[count_out == k][:200]:
            on_segment = [distance_to_segments(x, a, b) < 1e-9 * (1 + np.abs(x).max()) for x in (p, q)]
            assert (on_segment[0] & on_segment[1]).any(), (k, p, q)


def distance_to_segments(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", x - a, d) / np.einsum("ij,ij->i", d, d), 0, 1)
    return np.linalg.norm(a + t[:, None] * d - x, axis=1)


def local_copy(path, folder):
    """``path`` copied into ``folder`` with the MTL and PNG files beside it; the copy's path."""
    for sibling in path.parent.glob("*"):
        if sibling.suffix in (".mtl", ".png") or sibling == path:
            shutil.copy(sibling, folder / sibling.name)
    return folder / path.name


def welded(mesh: Mesh) -> np.ndarray:
    return np.unique(mesh.positions, axis=0, return_inverse=True)[1].reshape(-1)
