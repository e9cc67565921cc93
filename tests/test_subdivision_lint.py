"""Q101-Q103 where the renderer draws them (design.md, "Subdivision"): on the mesh refined to the level of
``--subdivision`` / ``--profile``, reported on base faces.

Truth: OpenSubdiv's Far refinement of Spot's control mesh (the committed fixtures, tests/oracle/), linted as a
mesh of its own, gives each base face's worst value; the figures of issue 56 (Far at L1-L3 with Q101 on the
refined quads, Blender's modifier agreeing: Spot 90 / 18 / 4 errors under cornersPlus1, 115 / 44 under all;
the UV sphere's pole rows 16 -> 8 -> 4 -> 2 texels)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run, write
from helpers.corpus import SHARED_MESHES
from helpers.osd_fixtures import load_fixture

from affinity.findings import FileReport, RefinedColumns, RuleHits, report_from_bytes, report_to_bytes
from affinity.lint import lint_pass
from affinity.loaders import load
from affinity.mesh import Mesh
from affinity.settings import Settings

SPOT = SHARED_MESHES / "spot_control_mesh.obj"
SPHERE = SHARED_MESHES / "gen_uv_sphere_64x32.obj"
ROOK = SHARED_MESHES / "usd" / "OpenChessSet" / "assets" / "Rook" / "Rook.usd"


def _need(path):
    if not path.is_file():
        pytest.skip(f"{path} is absent")
    return str(path)


def _findings(*args) -> list[dict]:
    done = run("check", "--isolated", "--no-cache", "--format", "json", *args)
    assert done.returncode in (0, 1), done.stderr
    return json.loads(done.stdout)["findings"]


@pytest.mark.parametrize(("level", "errors"), [(1, 90), (2, 18), (3, 4)])
def test_spot_under_cornersPlus1_keeps_the_crease_far_measures(level, errors):
    """Issue 56's table: Spot's control mesh (1024 texture) at L1 / L2 / L3 has 90 / 18 / 4 base faces with a
    Q101 error, within 2 (Far + Q101 on the refined quads, Blender agreeing)."""
    found = _findings(_need(SPOT), "--select", "Q101", "--texture-size", "1024", "--subdivision", f"level:{level}")
    assert abs(sum(f["level"] == "error" for f in found) - errors) <= 2
    assert {f["subdivision_level"] for f in found} == {level}
    assert all(f"at L{level}," in f["message"] for f in found)


@pytest.mark.parametrize(("level", "errors"), [(1, 115), (2, 44)])
def test_spot_under_the_linear_rule(level, errors):
    found = _findings(_need(SPOT), "--select", "Q101", "--subdivision", f"level:{level}", "--fvar-interpolation", "all")
    assert abs(sum(f["level"] == "error" for f in found) - errors) <= 2


def test_each_base_face_reads_its_worst_refined_face_of_fars_refinement():
    """The findings at L1-L3 are, face for face, the worst Q101 over Far's refined quads of each base face (the
    fixture's level points and uv under cornersPlus1, linted as a mesh of their own)."""
    mesh = load(_need(SPOT))
    arrays = load_fixture("spot_control_mesh")
    for level in (1, 2, 3):
        key = f"L{level}_edgeAndCorner"
        faces = arrays[f"{key}_faces"].astype(np.int64)
        base = arrays[f"{key}_base"].astype(np.int64)
        far = Mesh(path="far", positions=arrays[f"{key}_positions"], face_start=4 * np.arange(len(faces) + 1),
                   corner_vertex=faces.ravel(), face_line=mesh.face_line[base],
                   texcoords=arrays[f"{key}_cornersPlus1_uv"],
                   corner_texcoord=arrays[f"{key}_cornersPlus1_uv_faces"].astype(np.int64).ravel())
        [far_hits] = lint_pass(far, Settings(select=["Q101"])).hits
        worst = np.full(mesh.n_faces, -np.inf)
        np.maximum.at(worst, base[far_hits.faces], far_hits.values)
        [ours] = lint_pass(mesh, Settings(select=["Q101"], subdivision=f"level:{level}")).hits
        assert np.array_equal(ours.faces, np.flatnonzero(np.isfinite(worst)))
        np.testing.assert_allclose(ours.values, worst[ours.faces], rtol=1e-6)
        assert np.array_equal(ours.refined.flagged, np.bincount(base[far_hits.faces])[ours.faces])


def test_the_uv_spheres_pole_rows_only_halve():
    """The pole rows of the 64 x 32 UV sphere read 16 texels on the cage, then 8 / 4 / 2 at L1 / L2 / L3."""
    path = _need(SPHERE)
    for level, texels in ((0, 16), (1, 8), (2, 4), (3, 2)):
        found = _findings(path, "--select", "Q101", "--subdivision", f"level:{level}" if level else "cage")
        pole = [f["value"] for f in found if f["face"] < 64 or f["face"] >= 2048 - 64]
        assert len(pole) == 128 and np.allclose(pole, texels, rtol=1e-6), level


def test_profile_game_keeps_todays_cage_findings_and_obj_meshes_stay_cages_under_auto():
    path = _need(SPOT)
    cage = _findings(path, "--subdivision", "cage")
    assert _findings(path) == cage
    assert _findings(path, "--profile", "game") == cage
    assert _findings(path, "--profile", "blender-render") == cage  # an OBJ names no scheme: auto reads its cage
    assert all("subdivision_level" not in f for f in cage)


def test_a_chess_piece_under_blender_render_is_measured_at_level_two_on_its_base_faces():
    """The Open Chess Set's rook (its mesh subdivides: USD's fallback catmullClark): --profile blender-render
    reports Q101 at L2 on base faces; --profile game gives exactly the cage findings."""
    path = _need(ROOK)
    rendered = _findings(path, "--profile", "blender-render")
    assert rendered and {f["subdivision_level"] for f in rendered if f["code"] == "Q101"} == {2}
    faces = load(path).n_faces
    assert all(0 <= f["face"] < faces for f in rendered)
    assert _findings(path, "--profile", "game") == _findings(path, "--subdivision", "cage")


def test_film_draws_the_limit_surface_where_no_split_creases(tmp_path):
    path = _need(ROOK)
    done = run("check", "--isolated", "--no-cache", "--format", "json", "--profile", "film", path)
    assert not [f for f in json.loads(done.stdout)["findings"] if f["code"] in ("Q101", "Q102", "Q103")]
    assert "limit surface" in done.stderr


def test_q103_is_not_measured_on_a_usd_mesh_drawn_subdivided(tmp_path):
    """Authored normals on a mesh that subdivides are ignored by renderers: under a profile that subdivides,
    no Q103 and one note for the prim; under game the cage's Q103 stands."""
    pxr = pytest.importorskip("pxr")
    from pxr import Sdf, Usd, UsdGeom

    path = tmp_path / "normals.usda"
    stage = Usd.Stage.CreateNew(str(path))
    mesh = UsdGeom.Mesh.Define(stage, "/Panel")
    mesh.GetPointsAttr().Set([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])
    mesh.GetFaceVertexCountsAttr().Set([4])
    mesh.GetFaceVertexIndicesAttr().Set([0, 1, 2, 3])
    normals = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("normals", Sdf.ValueTypeNames.Normal3fArray,
                                                      UsdGeom.Tokens.faceVarying)
    normals.Set([(0, 0, 1), (0, 0, 1), (0.8, 0, 0.6), (0, 0, 1)])
    stage.GetRootLayer().Save()
    assert pxr is not None
    game = run("check", "--isolated", "--no-cache", "--format", "json", "--select", "Q103", str(path))
    assert [f["code"] for f in json.loads(game.stdout)["findings"]] == ["Q103"]
    drawn = run("check", "--isolated", "--no-cache", "--format", "json", "--select", "Q103", "--profile",
                "blender-viewport", str(path))
    assert json.loads(drawn.stdout)["findings"] == []
    assert drawn.stderr.count("/Panel: Q103 not measured") == 1


def test_the_profile_is_stated_in_settings_json_and_sarif(tmp_path):
    obj = write(tmp_path, "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                       "f 1/1 2/2 3/3 4/4\n")
    shown = run("check", "--isolated", "--show-settings", "--profile", "blender-render", str(obj)).stdout
    assert 'profile = "blender-render"' in shown and 'subdivision = "auto"' in shown
    assert 'fvar-interpolation = "cornersPlus1"' in shown
    as_json = json.loads(run("check", "--isolated", "--format", "json", "--profile", "film", str(obj)).stdout)
    assert as_json["settings"]["profile"] == "film"
    sarif = json.loads(run("check", "--isolated", "--format", "sarif", "--profile", "storm", str(obj)).stdout)
    assert sarif["runs"][0]["properties"]["profile"] == "storm"


def test_bad_subdivision_values_are_usage_errors(tmp_path):
    obj = write(tmp_path, "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    done = run("check", "--isolated", "--subdivision", "level:x", str(obj))
    assert done.returncode == 2 and "level:N" in done.stderr
    write(tmp_path, "affinity.toml", 'subdivision = "twice"\n')
    done = run("check", str(obj), cwd=tmp_path)
    assert done.returncode == 2 and "subdivision" in done.stderr


def test_a_stored_report_keeps_where_its_findings_were_refined():
    hits = RuleHits("Q101", np.array([3, 5]), np.array([10, 12]), np.array([2.0, 9.0]), 0.5,
                    np.zeros(2, dtype=np.int32), details=["at L2, 1 of 16 refined faces flagged", None],
                    refined=RefinedColumns(np.array([2, 2], np.int8), np.array([1, 4], np.int32),
                                           np.array([16, 16], np.int32)))
    back = report_from_bytes(report_to_bytes(FileReport("m.obj", hits=[hits]))).hits[0]
    for name in RefinedColumns.ARRAYS:
        assert np.array_equal(getattr(back.refined, name), getattr(hits.refined, name))
