"""One finding per defect (design.md): no Q101 from a collapsed uv (Q301), no Q101-Q103 on a quad without
area or a bow-tie, whatever rules are selected; a pole quad (one repeated corner) keeps its findings.

The fixture's quads are built so that which ones collapse is known by construction; the pole quads of the
shared lat-long sphere carry the closed-form value of the split's uv error, their whole u width.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run, write

from affinity.lint import lint_mesh
from affinity.loaders import load
from affinity.mesh import mesh_from_polygons
from affinity.settings import Settings

SQUARE = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
TRAPEZOID = [[-1, 0, 0], [1, 0, 0], [0.5, 1, 0], [-0.5, 1, 0]]
UNIT_UV = [[0, 0], [1, 0], [1, 1], [0, 1]]
#: uv that collapse: to a point, to a line (all four corners on the diagonal u = v), to a line with a
#: repeated corner; then uv with area (a uv triangle: one repeated corner, and a skewed quad).
COLLAPSED_UV = {
    "point": [[0.3, 0.3]] * 4,
    "line": [[0, 0], [0.2, 0.2], [0.7, 0.7], [0.1, 0.1]],
    "segment": [[0, 0.5], [1, 0.5], [1, 0.5], [0, 0.5]],
}
SOUND_UV = {
    "triangle": [[0, 0], [1, 0], [0.5, 1], [0.5, 1]],
    "skewed": [[0, 0], [1, 0], [0.9, 0.2], [0.1, 0.9]],
}


def separate_quads(quads, texcoords, **attributes):
    """One quad per (4, 3) corner list, each with its own four vertices; attributes per vertex."""
    flat = {name: np.asarray(values, float).reshape(len(quads) * 4, -1) for name, values in attributes.items()}
    return mesh_from_polygons("test.obj", np.reshape(quads, (-1, 3)), np.arange(4 * len(quads)).reshape(-1, 4),
                              texcoords=np.reshape(texcoords, (-1, 2)), **flat)


def by_code(hits) -> dict[str, set[int]]:
    return {h.code: set(h.faces.tolist()) for h in hits}


@pytest.fixture
def collapsed_uv_mesh():
    """Trapezoids (a crease on any non-affine uv) carrying the collapsed uv, then the sound ones."""
    uvs = [*COLLAPSED_UV.values(), *SOUND_UV.values()]
    return separate_quads([TRAPEZOID] * len(uvs), uvs)


@pytest.mark.parametrize("select", [None, ["Q101"], ["Q1", "Q3"], ["Q101", "Q302"]])
def test_a_collapsed_uv_gets_q301_and_no_q101_whatever_is_selected(collapsed_uv_mesh, select):
    found = by_code(lint_mesh(collapsed_uv_mesh, Settings(select=select)))
    collapsed, sound = set(range(len(COLLAPSED_UV))), set(range(len(COLLAPSED_UV), 5))
    assert found["Q101"] == sound, "every sound uv on a trapezoid is flagged, no collapsed one"
    if select is None or "Q3" in select:
        assert found["Q301"] == collapsed


def test_the_cause_says_what_it_breaks(tmp_path):
    obj = "".join(f"v {x} {y} {z}\n" for x, y, z in TRAPEZOID) + "vt 0.3 0.3\nf 1/1 2/1 3/1 4/1\n"
    path = write(tmp_path, "point.obj", obj)
    result = run("check", "--format", "json", str(path))
    (finding,) = json.loads(result.stdout)["findings"]
    assert finding["code"] == "Q301" and finding["message"].endswith("so Q101 is not measured on it")


def test_quads_without_area_and_bowties_get_no_q101_to_q103_but_a_pole_keeps_them():
    flat = [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]  # four corners on a line: no area
    bowtie = [[0, 0, 0], [1, 1, 0], [1, 0, 0], [0, 1, 0]]
    pole = [[-1, 0, 0], [1, 0, 0], [0, 1, 0], [0, 1, 0]]  # one repeated corner: a triangle
    rng = np.random.default_rng(7)
    colors = rng.uniform(size=(12, 3))
    normals = rng.normal(size=(12, 3)) * 0.3 + [0, 0, 1]
    mesh = separate_quads([flat, bowtie, pole], [UNIT_UV] * 3, colors=colors, normals=normals)
    for select in (None, ["Q1"]):
        found = by_code(lint_mesh(mesh, Settings(select=select)))
        for code in ("Q101", "Q102", "Q103"):
            assert found.get(code, set()) <= {2}, code
        assert 2 in found["Q101"]
    found = by_code(lint_mesh(mesh, Settings()))
    assert found["Q201"] >= {0, 2} and found["Q204"] == {1}


def test_the_shared_meshes_carry_one_finding_per_defect(manifest_entry, shared_meshes):
    mesh = load(str(shared_meshes / manifest_entry["file"]))
    hits = lint_mesh(mesh, Settings())
    found = by_code(hits)
    assert not found.get("Q101", set()) & found.get("Q301", set())
    scored = set().union(*(found.get(code, set()) for code in ("Q101", "Q102", "Q103")))
    assert not scored & found.get("Q204", set())
    zero_area = {f for h in hits if h.code == "Q201" for f, d in zip(h.faces.tolist(), h.details or [])
                 if d and d.startswith("it has no area")}
    assert not scored & zero_area


def test_the_pole_quads_of_the_lat_long_sphere_keep_their_exact_q101(shared_meshes):
    mesh = load(str(shared_meshes / "gen_uv_sphere_64x32.obj"))
    hits = {h.code: h for h in lint_mesh(mesh, Settings())}
    poles = hits["Q201"].faces
    assert len(poles) == 128 and hits["Q201"].details is None, "a pole quad has area: nothing taken over"
    q101 = dict(zip(hits["Q101"].faces.tolist(), hits["Q101"].values.tolist()))
    # The split's worst uv error on a pole quad is its whole u width, 1/64 of the 1024 texels.
    np.testing.assert_allclose([q101[f] for f in poles.tolist()], 1024 / 64, rtol=1e-9)
