"""``affinity fix`` on a USD stage: an override layer that sublayers the input and overrides only the fixed meshes."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run

pytest.importorskip("pxr")

from affinity.fix import FixSettings, plan_fix, refine_mesh
from affinity.loaders import load

#: A trapezoid (Q101) beside a square, sharing an edge, in a left-handed mesh under a rotation,
#: translation and scale; and a second mesh that needs no fix.
STAGE = """#usda 1.0
(
    upAxis = "Z"
    metersPerUnit = 0.01
    defaultPrim = "World"
)

def Xform "World"
{
    double3 xformOp:translate = (10, -2, 1)
    float3 xformOp:rotateXYZ = (30, 0, 45)
    float3 xformOp:scale = (2, 2, 2)
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale"]

    def Mesh "Panel"
    {
        uniform token orientation = "leftHanded"
        point3f[] points = [(-1, 0, 0), (1, 0, 0), (0.5, 1, 0), (-0.5, 1, 0), (1, -1, 0), (-1, -1, 0)]
        int[] faceVertexCounts = [4, 4]
        int[] faceVertexIndices = [0, 3, 2, 1, 0, 1, 4, 5]
        texCoord2f[] primvars:st = [(0, 0), (0, 1), (1, 1), (1, 0), (0, 0), (1, 0), (1, -1), (0, -1)] (
            interpolation = "faceVarying"
        )
        float[] primvars:weight = [1, 2, 3, 4, 5, 6] (
            interpolation = "vertex"
        )
    }

    def Mesh "Untouched"
    {
        point3f[] points = [(5, 0, 0), (6, 0, 0), (6, 1, 0), (5, 1, 0)]
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
    }
}
"""


def test_override_layer_composes_to_the_fixed_mesh_and_leaves_the_input_alone(tmp_path):
    from pxr import Sdf, Usd, UsdGeom

    path = tmp_path / "stage.usda"
    path.write_text(STAGE)
    result = run("fix", "--max-refine", "24", str(path))
    assert result.returncode == 0, result.stderr
    assert path.read_text() == STAGE
    # USD's default scheme subdivides the panel: one note says its subdivided surface changes; none for the other
    notes = [line for line in result.stdout.splitlines() if ": note: " in line]
    assert len(notes) == 1 and "/World/Panel: subdivisionScheme catmullClark" in notes[0], result.stdout
    out = tmp_path / "stage.fixed.usda"
    layer = Sdf.Layer.FindOrOpen(str(out))
    assert list(layer.subLayerPaths) == ["stage.usda"]
    assert [str(p.path) for p in layer.rootPrims] == ["/World"]
    assert [p.name for p in layer.GetPrimAtPath("/World").nameChildren] == ["Panel"]  # only the fixed mesh
    assert layer.GetPrimAtPath("/World").specifier == Sdf.SpecifierOver
    stage = Usd.Stage.Open(str(out))
    assert UsdGeom.GetStageUpAxis(stage) == "Z" and UsdGeom.GetStageMetersPerUnit(stage) == 0.01
    assert stage.GetPrimAtPath("/World/Panel").GetAttribute("primvars:weight").Get() is None  # blocked

    original = load(path)
    expected = refine_mesh(original, plan_fix(original, FixSettings(max_refine=24))).mesh
    fixed = load(out)  # composed by pxr, read as the check reads it
    # the trapezoid in 23 x 23, the square beside it cut into quads closing to the 23 segments of their edge,
    # the other mesh: quads only
    assert fixed.n_faces == expected.n_faces > 23 * 23 + 2 and (fixed.face_sizes == 4).all()
    for name, index in (("positions", "corner_vertex"), ("texcoords", "corner_texcoord")):
        np.testing.assert_allclose(getattr(fixed, name)[getattr(fixed, index)],
                                   getattr(expected, name)[getattr(expected, index)], atol=1e-5)
    check = run("check", "--isolated", str(out))
    assert check.returncode == 0, check.stdout


def test_dry_run_numbers_usd_faces_as_the_check_does(tmp_path):
    import json

    path = tmp_path / "stage.usda"
    # a clean square first, then the trapezoid: its face counts from 0 within its prim, as in the check's JSON
    path.write_text("""#usda 1.0
def Mesh "First"
{
    point3f[] points = [(5, 0, 0), (6, 0, 0), (6, 1, 0), (5, 1, 0)]
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 1, 2, 3]
}

def Mesh "Panel"
{
    point3f[] points = [(-1, 0, 0), (1, 0, 0), (0.5, 1, 0), (-0.5, 1, 0)]
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 1, 2, 3]
    texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1)] (
        interpolation = "vertex"
    )
}
""")
    checked = json.loads(run("check", "--format", "json", "--isolated", str(path)).stdout)["findings"]
    planned = json.loads(run("fix", "--dry-run", "--format", "json", "--max-refine", "24", str(path)).stdout)
    refine = planned["files"][0]["refine"]
    assert [(r["prim"], r["face"]) for r in refine] == [(f["prim"], f["face"]) for f in checked] == [("/Panel", 0)]
    assert refine[0]["where"] == f"{path}:/Panel:face 0"


def test_the_shared_knight_is_refined_under_the_default_profile_with_one_note_per_subdividing_mesh(
        shared_meshes, tmp_path):
    import shutil

    folder = shutil.copytree(shared_meshes / "usd" / "OpenChessSet" / "assets" / "Knight", tmp_path / "Knight")
    result = run("fix", str(folder / "Knight.usd"))
    assert result.returncode in (0, 1), result.stderr
    notes = [line for line in result.stdout.splitlines() if ": note: " in line]
    # the knight's one drawn mesh has no authored scheme: USD's default, Catmull-Clark, subdivides it
    assert len(notes) == 1 and "/Knight/Geom/Render: subdivisionScheme catmullClark" in notes[0], result.stdout
    fixed = load(folder / "Knight.fixed.usd")
    original = load(folder / "Knight.usd")
    assert fixed.n_faces > original.n_faces
    assert np.count_nonzero(fixed.face_sizes != 4) == np.count_nonzero(original.face_sizes != 4)


def test_under_a_subdividing_profile_every_flagged_quad_is_left_subdivided(tmp_path):
    from affinity.fix.plan import profile_subdivides
    from affinity.settings import Settings

    path = tmp_path / "stage.usda"
    path.write_text(STAGE)
    mesh = load(path)
    plan = plan_fix(mesh, FixSettings(subdivided=True))
    assert plan.empty and plan.left_reasons.tolist() == ["subdivided"] and plan.faces_added == 0
    # the hook: a check of the cage (today's settings, or a level 0) refines; a subdividing one does not
    assert not profile_subdivides(Settings())
    assert not profile_subdivides(Settings(subdivision="level:0"))
    assert profile_subdivides(Settings(subdivision="level:2"))
    assert profile_subdivides(Settings(subdivision="limit"))
    assert profile_subdivides(Settings(profile="film"))
    assert not profile_subdivides(Settings(profile="film"), scheme_subdivides=False)  # an OBJ draws its cage
    assert not profile_subdivides(Settings(profile="storm"))


def test_the_shared_knight_under_a_subdividing_profile_is_left_subdivided(shared_meshes, tmp_path):
    """What you check is what you fix: blender-render checks level 2 of the knight (USD's fallback scheme
    subdivides it), so the cage's flagged quads are left ``subdivided`` and nothing is written."""
    import shutil

    folder = shutil.copytree(shared_meshes / "usd" / "OpenChessSet" / "assets" / "Knight", tmp_path / "Knight")
    cage = json.loads(run("fix", "--dry-run", "--format", "json", str(folder / "Knight.usd")).stdout)["files"][0]
    drawn = json.loads(run("fix", "--dry-run", "--format", "json", "--profile", "blender-render",
                           str(folder / "Knight.usd")).stdout)["files"][0]
    assert cage["refine"] and not drawn["refine"]
    assert drawn["left"] and {left["reason"] for left in drawn["left"]} == {"subdivided"}
