"""The 3-D view's data (affinity.report.scene3d): arrays that rebuild the mesh, levels that agree with the lint's
JSON, a budget that keeps flagged faces and their neighbours, JSON that cannot close its script tag."""

from __future__ import annotations

import base64
import io
import json

import numpy as np
import pytest
from helpers.cli import run
from helpers.corpus import SHARED_MESHES

from affinity.mesh import mesh_from_polygons
from affinity.report.scene3d import kept_faces, script_json

SPOT = SHARED_MESHES / "spot_control_mesh.obj"


def _array(text: str, dtype) -> np.ndarray:
    return np.frombuffer(base64.b64decode(text), dtype=np.dtype(dtype).newbyteorder("<"))


def _grid(n: int):
    """An n x n grid of unit quads in the plane z = 0, faces row by row."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    positions = np.stack([j.ravel(), i.ravel(), np.zeros(i.size)], axis=1).astype(float)
    a = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    return mesh_from_polygons("grid", positions, np.stack([a, a + 1, a + n + 2, a + n + 1], axis=1))


def test_budget_keeps_every_face_when_it_fits():
    assert kept_faces(_grid(4), np.zeros(16, dtype=bool), 16).all()


def test_budget_keeps_flagged_faces_and_whole_rings_of_neighbours():
    mesh = _grid(9)
    flagged = np.zeros(81, dtype=bool)
    flagged[40] = True  # the centre face (row 4, column 4)
    rows, columns = np.divmod(np.arange(81), 9)
    ring = np.maximum(abs(rows - 4), abs(columns - 4))  # vertex-neighbour rings are squares about it
    assert (kept_faces(mesh, flagged, 9) == (ring <= 1)).all()  # 9 faces: the face and its first ring
    assert (kept_faces(mesh, flagged, 30) == (ring <= 2)).all()  # 25 fit, 49 would not
    assert (kept_faces(mesh, flagged, 1) == flagged).all()  # never fewer than the flagged faces


def test_script_json_cannot_end_its_script_and_round_trips():
    data = {"group": "</script><img src=x onerror=alert(1)><!--", "line": "a\u2028b"}
    text = script_json(data)
    assert "<" not in text and "\u2028" not in text
    assert json.loads(text) == data


def _result(path):
    from affinity.pipeline.check import load_and_check
    from affinity.report.build import MeshResult
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    file, mesh = load_and_check(str(path), Settings())
    return MeshResult(MeshInput(str(path), path.name), file, Settings(), mesh=mesh, shown="Q101",
                      camera=((3, 0, 0), (0, 0, 0), 40), up="y")  # the renders show uv, as collect_mesh picks


@pytest.mark.skipif(not SPOT.is_file(), reason="../shared/meshes is absent")
def test_view_data_rebuilds_spot_and_levels_agree_with_the_lint(tmp_path):
    """Spot (quads, triangles and pentagons): the embedded corners give back every face's positions, fanned as
    the renderer fans them, and each face's outline level is the worst level the lint's JSON gives it."""
    from affinity.loaders import load
    from affinity.report.scene3d import view_data

    data, notes = view_data(_result(SPOT))
    assert notes == []
    positions = _array(data["positions"], np.float32).reshape(-1, 3)
    corners = _array(data["corners"], np.uint32).reshape(-1, 4)
    faces = _array(data["faces"], np.uint32)
    reference = load(str(SPOT))
    assert sorted(set(faces.tolist())) == list(range(reference.n_faces))
    for face in [int(np.flatnonzero(reference.face_sizes == k)[0]) for k in (3, 4, 5)]:
        start, end = reference.face_start[face], reference.face_start[face + 1]
        polygon = reference.positions[reference.corner_vertex[start:end]]
        drawn = positions[corners[faces == face]]  # (fan, 4, 3): (0, i, i+1, i+1) for n-gons
        if len(polygon) == 4:
            np.testing.assert_allclose(drawn, polygon[None], atol=1e-6)
            continue
        np.testing.assert_allclose(drawn[:, 0], np.broadcast_to(polygon[0], drawn[:, 0].shape), atol=1e-6)
        np.testing.assert_allclose(np.concatenate([drawn[:1, 1], drawn[:, 2]]), polygon[1:], atol=1e-6)
    lint = json.loads(run("check", "--format", "json", str(SPOT)).stdout)
    order = ["error", "warning", "info"]
    worst = {}
    for finding in lint["findings"]:
        rank = order.index(finding["level"]) + 1
        worst[finding["face"]] = min(worst.get(finding["face"], rank), rank)
    levels = _array(data["levels"], np.uint8)
    assert {int(f): int(level) for f, level in zip(faces, levels) if level} == worst


def test_over_budget_the_view_keeps_flagged_faces_and_says_what_it_left_out(tmp_path):
    """A 6 x 6 grid whose one quad has a bent uv: with a budget of 10 render quads the view keeps that face and its
    8 vertex neighbours, and its note counts the other 27."""
    from affinity.report.scene3d import view_data

    n = 6
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    uv = np.stack([j.ravel(), i.ravel()], axis=1) / n
    uv[3 * (n + 1) + 3] += 0.05  # the vertex shared by faces 14, 15, 20, 21
    lines = [f"v {x} {y} 0" for y, x in zip(i.ravel(), j.ravel())] + [f"vt {u} {v}" for u, v in uv]
    a = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel() + 1
    lines += [f"f {p}/{p} {p + 1}/{p + 1} {p + n + 2}/{p + n + 2} {p + n + 1}/{p + n + 1}" for p in a]
    path = tmp_path / "grid.obj"
    path.write_text("\n".join(lines) + "\n")
    result = _result(path)
    flagged = sorted({int(face) for hits in result.file.hits for face in hits.faces})
    assert flagged == [14, 15, 20, 21]
    data, notes = view_data(result, budget=16)
    kept = sorted(set(_array(data["faces"], np.uint32).tolist()))
    rows, columns = np.divmod(np.arange(n * n), n)
    ring = [f for f in range(n * n) if 1 <= rows[f] <= 4 and 1 <= columns[f] <= 4]  # the flagged 2 x 2 and its ring
    assert kept == ring
    assert notes == [f"the 3-D view keeps the 4 flagged faces and their neighbourhoods: {n * n - 16} of {n * n} faces "
                     "are left out of it to keep the page small"]
    assert data["left_out"] == n * n - 16


def test_texture_is_embedded_at_most_2048_px_with_its_real_size(tmp_path):
    from PIL import Image

    from affinity.report.scene3d import view_data

    Image.new("RGB", (3000, 600), (200, 30, 30)).save(tmp_path / "wide.png")
    (tmp_path / "m.mtl").write_text("newmtl m\nmap_Kd wide.png\n")
    (tmp_path / "quad.obj").write_text("mtllib m.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")
    texture = view_data(_result(tmp_path / "quad.obj"))[0]["texture"]
    assert (texture["width"], texture["height"], texture["name"]) == (3000, 600, "wide.png")
    embedded = Image.open(io.BytesIO(base64.b64decode(texture["uri"].split(",", 1)[1])))
    assert embedded.size == (2048, 410)
    assert embedded.convert("RGB").getpixel((1000, 200)) == (200, 30, 30)
