"""Q201 vs Q204 for float32 slivers (issue 55): a quad whose four corner triangles all lie within rounding of
zero at the precision the file stores its points in is degenerate (Q201), not a bow-tie (Q204).

The truth: the same corner values read as float64 (an OBJ, with every digit) are a bow-tie by float64
rounding (two clockwise turns, computed here from cross products), and as float32 (a USD ``point3f[]``) their
largest corner triangle is within a few float32 ulps of the coordinates times the longest edge.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run

pytest.importorskip("pxr", reason="needs the usd extra (usd-core)")

#: Four points on a line through float32 rounding, in the folded order t = 0, 2, 1, 3 (a float32 sliver).
SLIVER = [(0.6100058555603027, 0.6158815622329712, 0.030651122331619263),
          (0.6091631650924683, 0.6141267418861389, 0.0301922969520092),
          (0.6095845103263855, 0.6150041818618774, 0.030421709641814232),
          (0.6087418794631958, 0.6132493615150452, 0.02996288612484932)]
#: A real bow-tie: its edges 0-1 and 2-3 cross.
BOWTIE = [(0.0, 0.0, 0.0), (2.0, 1.0, 0.0), (2.0, 0.0, 0.0), (0.0, 1.5, 0.0)]


def corner_turns(corners) -> np.ndarray:
    """(4,) the turn at each corner, (p_k - p_k-1) x (p_k+1 - p_k) along the quad's normal d02 x d13."""
    p = np.asarray(corners, dtype=np.float64)
    normal = np.cross(p[2] - p[0], p[3] - p[1])
    return np.array([np.cross(p[k] - p[k - 1], p[(k + 1) % 4] - p[k]) @ normal for k in range(4)])


def stage_of(folder, corners, name="quad.usda"):
    from pxr import Usd, UsdGeom

    path = folder / name
    stage = Usd.Stage.CreateNew(str(path))
    mesh = UsdGeom.Mesh.Define(stage, "/Quad")
    mesh.GetPointsAttr().Set(corners)  # point3f[]
    mesh.GetFaceVertexCountsAttr().Set([4])
    mesh.GetFaceVertexIndicesAttr().Set([0, 1, 2, 3])
    mesh.GetSubdivisionSchemeAttr().Set("none")
    stage.GetRootLayer().Save()
    return path


def codes(path) -> list[tuple[str, str]]:
    result = run("check", "--no-cache", "--isolated", "--format", "json", "--select", "Q2", str(path))
    assert result.returncode in (0, 1), result.stderr
    return [(f["code"], f["level"]) for f in json.loads(result.stdout)["findings"]]


def test_a_float32_sliver_is_degenerate_and_the_same_values_in_float64_a_bowtie(tmp_path):
    turns = corner_turns(SLIVER)
    assert (turns < 0).sum() == 2  # a bow-tie by float64 arithmetic
    longest = max(np.linalg.norm(np.subtract(SLIVER[k], SLIVER[k - 1])) for k in range(4))
    normal = np.linalg.norm(np.cross(np.subtract(SLIVER[2], SLIVER[0]), np.subtract(SLIVER[3], SLIVER[1])))
    # every corner triangle within 8 float32 ulps of the coordinates' magnitude times the longest edge
    assert np.abs(turns).max() / normal <= 8 * np.finfo(np.float32).eps * 0.62 * longest
    obj = tmp_path / "sliver.obj"
    obj.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in SLIVER) + "f 1 2 3 4\n")
    assert codes(obj) == [("Q204", "error")]
    assert codes(stage_of(tmp_path, SLIVER)) == [("Q201", "warning")]


def test_a_real_float32_bowtie_stays_a_bowtie(tmp_path):
    assert (corner_turns(BOWTIE) < 0).sum() == 2
    assert codes(stage_of(tmp_path, BOWTIE)) == [("Q204", "error")]


def test_the_bishops_slivers_are_q201_not_q204(shared_meshes, tmp_path):
    """The Bishop's float32 points written to an OBJ with every digit (float64 text: the old reading) give 52
    bow-ties; read from the USD layer (float32) those same faces are Q201 warnings and no Q204 is left."""
    from pxr import Usd, UsdGeom

    geometry = shared_meshes / "usd" / "OpenChessSet" / "assets" / "Bishop" / "Bishop_geom.usd"
    if not geometry.is_file():
        pytest.skip("the Open Chess Set is not in ../shared/meshes/usd")
    stage = Usd.Stage.Open(str(geometry))
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/Bishop/Geom/Render"))
    points = np.asarray(mesh.GetPointsAttr().Get(), dtype=np.float64)
    assert (np.asarray(mesh.GetFaceVertexCountsAttr().Get()) == 4).all()
    faces = np.asarray(mesh.GetFaceVertexIndicesAttr().Get()).reshape(-1, 4) + 1
    obj = tmp_path / "bishop.obj"
    obj.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in points.tolist())
                   + "".join(f"f {a} {b} {c} {d}\n" for a, b, c, d in faces.tolist()))

    def findings(path):
        result = run("check", "--no-cache", "--isolated", "--format", "json", "--select", "Q201,Q204", str(path))
        return json.loads(result.stdout)["findings"]

    folded = [f["face"] for f in findings(obj) if f["code"] == "Q204"]
    assert len(folded) == 52
    read = findings(geometry)
    assert not [f for f in read if f["code"] == "Q204"]
    q201 = {f["face"]: f["level"] for f in read if f["code"] == "Q201"}
    assert {face: q201.get(face) for face in folded} == dict.fromkeys(folded, "warning")
