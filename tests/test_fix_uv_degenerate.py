"""A uv-degenerate quad beside a refinement (issues 54, 55): cut into pieces, each piece would be uv-degenerate
too, so one Q301 would become one per piece (the shared chess set's fix went from 966 Q301 to 1020). The fix
leaves such a quad uncut, and its re-check counts a cut neighbour whose pieces multiply a finding it had.

Truths: ``affinity check`` of the written OBJ (the check's own JSON), the input's bytes, and the closed form of
the pieces (every bilinear blend of corners on one uv line lies on that line).
"""

from __future__ import annotations

import collections
import json

import numpy as np
import pytest
from helpers.cli import run, write

from affinity.fix import FixSettings, plan_fix
from affinity.loaders import load

#: Two unit squares side by side: face 0 has a trapezoid uv (Q101, refined at n = 5), face 1 a uv that
#: collapses to the segment (0.8, 0.5)-(0.9, 0.5) (Q301).
PAIR = ("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n"
        "vt 0.5 0\nvt 0.75 0\nvt 0.74 0.25\nvt 0.51 0.25\nvt 0.8 0.5\nvt 0.9 0.5\n"
        "f 1/1 2/2 5/3 4/4\n"
        "f 2/5 3/6 6/6 5/5\n")


def codes(path) -> collections.Counter:
    result = run("check", "--no-cache", "--isolated", "--format", "json", str(path))
    assert result.returncode in (0, 1), result.stderr
    return collections.Counter(f["code"] for f in json.loads(result.stdout)["findings"])


def test_a_uv_degenerate_neighbour_is_not_cut_and_keeps_its_one_q301(tmp_path):
    path = write(tmp_path, "pair.obj", PAIR)
    assert codes(path) == {"Q101": 1, "Q301": 1}
    fixed = run("fix", "--format", "json", "--isolated", str(path))
    assert fixed.returncode == 0, fixed.stdout + fixed.stderr
    entry = json.loads(fixed.stdout)["files"][0]
    assert [r["face"] for r in entry["refine"]] == [0] and entry["transitions"] == []
    assert entry["new_findings"] == [] and entry["left"] == []
    out = (tmp_path / "pair.fixed.obj").read_text().splitlines()
    assert "f 2/5 3/6 6/6 5/5" in out
    assert codes(tmp_path / "pair.fixed.obj") == {"Q301": 1}


def test_the_recheck_counts_a_cut_neighbour_whose_pieces_multiply_its_finding(tmp_path, monkeypatch):
    """With Q301's quads cuttable again (the merged tree's behaviour), the first build cuts face 1 into pieces
    that are all uv-degenerate: the re-check names it (Q301 on face 1), and the loop keeps it as it was."""
    import affinity.fix.loop as loop
    import affinity.fix.plan as plan_module

    monkeypatch.setattr(plan_module, "uncut_by_rule", lambda: ("Q201", "Q203", "Q204"))
    seen = []
    real = loop.verify

    def recording(mesh, plan, fix, baseline):
        flagged, new = real(mesh, plan, fix, baseline)
        seen.append((plan.transition_faces.tolist(), new))
        return flagged, new

    monkeypatch.setattr(loop, "verify", recording)
    mesh = load(write(tmp_path, "pair.obj", PAIR))
    plan = plan_fix(mesh, FixSettings())
    assert seen[0] == ([1], [{"code": "Q301", "face": 1}])
    assert seen[-1] == ([], []) and plan.transition_faces.tolist() == [] and plan.new_findings == []
    refined = plan.refined
    kept = np.flatnonzero(refined.source == 1)
    assert len(kept) == 1 and not refined.added[kept[0]]



GEOM = """#usda 1.0
(
    defaultPrim = "Pair"
)

def Mesh "Pair"
{
    int[] faceVertexCounts = [4, 4]
    int[] faceVertexIndices = [0, 1, 4, 3, 1, 2, 5, 4]
    point3f[] points = [(0, 0, 0), (1, 0, 0), (2, 0, 0), (0, 1, 0), (1, 1, 0), (2, 1, 0)]
    texCoord2f[] primvars:st = [(0.5, 0), (0.75, 0), (0.74, 0.25), (0.51, 0.25), (0.8, 0.5), (0.9, 0.5), (0.9, 0.5),
        (0.8, 0.5)] (
        interpolation = "faceVarying"
    )
    uniform token subdivisionScheme = "none"
}
"""

STAGE = """#usda 1.0
(
    defaultPrim = "Set"
)

def Xform "Set"
{
    def Mesh "A" (
        references = @./pair.usda@
    )
    {
    }

    def Mesh "B" (
        references = @./pair.usda@
    )
    {
        double3 xformOp:translate = (5, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
}
"""


def test_two_prims_of_one_mesh_fixed_once_keep_their_one_q301(tmp_path):
    """The same pair authored once and referenced by two prims (the chess set's knights in miniature): the
    fixed stage, as usd-core composes it, has no more Q301 than the input, and both prims read the uv-degenerate
    quad as authored (the class both inherit was not cut there)."""
    pytest.importorskip("pxr", reason="needs the usd extra (usd-core)")
    from pxr import Usd, UsdGeom

    write(tmp_path, "pair.usda", GEOM)
    stage = write(tmp_path, "set.usda", STAGE)
    before = codes(stage)
    assert before["Q301"] >= 1 and before["Q101"] >= 1
    fixed = run("fix", "--format", "json", "--isolated", str(stage))
    assert fixed.returncode == 0, fixed.stdout + fixed.stderr
    entry = json.loads(fixed.stdout)["files"][0]
    assert {r["prim"] for r in entry["refine"]} == {"/Set/A", "/Set/B"} and entry["transitions"] == []
    after = codes(tmp_path / "set.fixed.usda")
    assert after["Q301"] == before["Q301"] and after["Q101"] == 0
    composed = Usd.Stage.Open(str(tmp_path / "set.fixed.usda"))
    for prim in ("/Set/A", "/Set/B"):
        mesh = UsdGeom.Mesh(composed.GetPrimAtPath(prim))
        counts = np.array(mesh.GetFaceVertexCountsAttr().Get())
        assert len(counts) > 2 and (counts == 4).all()
        points = np.array(mesh.GetPointsAttr().Get())
        indices = np.array(mesh.GetFaceVertexIndicesAttr().Get()).reshape(-1, 4)
        # the face on the original corners (1, 0, 0), (2, 0, 0), (2, 1, 0), (1, 1, 0), uncut
        assert [p.tolist() for p in points[indices]].count([[1, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0]]) == 1
