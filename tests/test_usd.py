"""USD stages: the loader against a hand-written stage, the same meshes as OBJ, .usdc/.usdz
round trips, every bad input, the missing extra, and USD locations in every output format.

``tests/data/usd/scene.usda`` holds, under an Xform that scales by 2 and moves by
(10, 0, 0): quads and a triangle with indexed faceVarying ``st``, vertex
``displayColor`` and indexed ``primvars:normals``; a leftHanded mesh with uniform
colours; a mesh whose points are sampled at times 1 and 5; two instances of a
crate whose uv primvar is ``map1``; an invisible and a guide mesh; and a
PointInstancer. The expected values below are that file's, by hand.
"""

from __future__ import annotations

import doctest
import importlib.util
import json
import re
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import run, run_without
from helpers.sarif import assert_valid

import affinity.loaders.usd
from affinity.errors import MeshError
from affinity.lint import assumed_texture_note
from affinity.loaders import load
from affinity.loaders.objwriter import write_obj
from affinity.loaders.usd import UsdOptions, _Primvar, colors_per_vertex, corner_index
from affinity.pipeline.check import check_file, check_files
from affinity.pipeline.files import MESH_SUFFIXES, collect_paths
from affinity.rules import RULES
from affinity.settings import Settings

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "tests" / "data" / "usd" / "scene.usda"

requires_usd = pytest.mark.skipif(importlib.util.find_spec("pxr") is None, reason="needs the usd extra (usd-core)")

PRIMS = ["/World/Panel", "/World/Mirror", "/World/Animated", "/World/CrateA/Box", "/World/CrateB/Box",
         "/World/Scatter/Prototypes/Pebble"]
Z = (0, 0, 1)


def world(points, offset=(0, 0, 0)):
    """Points of a prim under /World (scale 2, then move by (10, 0, 0)), after a local ``offset``."""
    return [(2 * (x + offset[0]) + 10, 2 * (y + offset[1]), 2 * (z + offset[2])) for x, y, z in points]


def crate(offset):
    quad = world([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], offset)
    tri = world([(1, 0, 0), (1.5, 0.5, 0), (1, 1, 0)], offset)
    return [
        (quad, [(0, 0), (0.5, 0), (0.5, 0.5), (0, 0.5)], [(1, 1, 0)] * 4, [Z] * 4),
        (tri, [(0.5, 0), (0.75, 0.25), (0.5, 0.5)], [(1, 1, 0)] * 3, [Z] * 3),
    ]


#: Per face in stage order: (corner positions, uv, colours, normals), as written in scene.usda.
FACES = [
    # /World/Panel
    (world([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]), [(0, 0), (1, 0), (1, 1), (0, 1)],
     [(0, 0, 0), (1, 0, 0), (0, 0, 0), (1, 0, 0)], [Z] * 4),
    (world([(2, 0, 0), (4, 0, 0), (3.5, 1, 0), (2.5, 1, 0)]), [(0, 0), (1, 0), (1, 1), (0, 1)],
     [(0.25, 0, 0.5), (0.75, 0, 0.5), (0.625, 1, 0.5), (0.375, 1, 0.5)], [Z, (0, 0.6, 0.8), (0, 0.6, 0.8), Z]),
    (world([(5, 0, 0), (6, 0, 0), (5, 1, 0)]), [(0, 0), (1, 0), (0, 1)], [(0, 1, 1)] * 3, [Z] * 3),
    # /World/Mirror: leftHanded 0-3-2-1 and 1-2-4 read as 0-1-2-3 and 1-4-2, uniform red and blue
    (world([(0, 2, 0), (1, 2, 0), (1, 3, 0), (0, 3, 0)]), [(0, 0), (1, 0), (1, 1), (0, 1)], [(1, 0, 0)] * 4, [Z] * 4),
    (world([(1, 2, 0), (2, 2, 0), (1, 3, 0)]), [(1, 0), (2, 0), (1, 1)], [(0, 0, 1)] * 3, [Z, (1, 0, 0), Z]),
    # /World/Animated at its earliest sample (time 1)
    (world([(0, 4, 0), (1, 4, 0), (1, 5, 0), (0, 5, 0)]), [(0, 0), (1, 0), (1, 1), (0, 1)], [(0.5, 0.5, 0.5)] * 4,
     [Z] * 4),
    *crate((0, 6, 0)),
    *crate((2, 6, 0)),
    # /World/Scatter/Prototypes/Pebble, once, where it is defined
    (world([(0, 0, 0), (0.5, 0, 0), (0, 0.5, 0)]), [(0, 0), (1, 0), (0, 1)], [(0, 0.5, 0)] * 3, [Z] * 3),
]


def check(*args: str):
    """``affinity check ARGS`` from the repository root."""
    return run("check", *args, cwd=ROOT)


def face_values(mesh, name: str) -> list[list[tuple]]:
    """Every face's corner values of ``name`` as nested lists of tuples."""
    out = []
    for f in range(mesh.n_faces):
        corners = np.arange(mesh.face_start[f], mesh.face_start[f + 1])[None]
        out.append([tuple(v) for v in mesh.corner_attribute(name, corners)[0].tolist()])
    return out


def test_doctests():
    assert doctest.testmod(affinity.loaders.usd).failed == 0


@requires_usd
def test_scene_reads_exactly_what_was_written():
    mesh = load(SCENE)
    assert mesh.group_names == PRIMS
    assert mesh.prim_face_start.tolist() == [0, 3, 5, 6, 8, 10, 11]
    assert mesh.face_group.tolist() == [0, 0, 0, 1, 1, 2, 3, 3, 4, 4, 5]
    assert mesh.counts() == {"faces": 11, "quads": 6, "triangles": 5, "ngons": 0}
    assert (mesh.face_line == 0).all()
    assert (mesh.up_axis, mesh.meters_per_unit) == ("Z", 0.01)
    for k, name in enumerate(["positions", "texcoords", "colors"]):  # all exact in float32
        expected = [[tuple(map(float, v)) for v in face[k]] for face in FACES]
        assert face_values(mesh, name) == expected, name
    normals = [v for face in face_values(mesh, "normals") for v in face]  # (0, 0.6, 0.8) is not exact in float32
    np.testing.assert_allclose(normals, [v for face in FACES for v in face[3]], rtol=0, atol=1e-7)


@requires_usd
def test_notes_name_what_was_not_checked():
    notes = load(SCENE).notes
    assert notes == [
        "2 mesh prims skipped (invisible, or guide/proxy purpose)",
        ("PointInstancer /World/Scatter: 3 copies of 1 prototype not expanded "
         "(each prototype mesh is checked once, where it is defined)"),
        ("6 of 6 mesh prims subdivide (subdivisionScheme catmullClark, authored or USD's default): the findings "
         "are for the cage, which is what Storm draws at its default complexity and what game engines draw"),
    ]


@requires_usd
def test_time_option_reads_another_sample():
    mesh = load(SCENE, UsdOptions(time=5))
    animated = face_values(mesh, "positions")[5]
    assert animated == [tuple(map(float, p)) for p in world([(0, 4, 1), (2, 4, 1), (1, 5, 1), (0, 5, 1)])]


@requires_usd
def test_uv_primvar_option_chooses_the_primvar():
    mesh = load(SCENE, UsdOptions(uv_primvar="map1"))
    has_uv = ~np.isnan(mesh.corner_attribute("texcoords", mesh.faces_of_size(4)[1])).any(axis=(1, 2))
    assert has_uv.tolist() == [False, False, False, False, True, True]  # the two crates' quads only
    missing = load(SCENE, UsdOptions(uv_primvar="UVMap"))
    assert missing.texcoords is None
    assert missing.notes[-1] == "no mesh has the primvar 'UVMap': texture coordinates not checked"


def hits_by_code(report) -> dict:
    return {h.code: (h.faces.tolist(), h.values.tolist()) for h in report.hits}


#: Every measured quad flagged, so findings compare face for face and value for value; Q201 and Q301 keep
#: their defaults (at a huge threshold every quad would be collapsed, and get no Q101-Q103).
FLAG_ALL = Settings(thresholds={code: -1.0 for code, rule in RULES.items()
                                if rule.default_threshold is not None and code not in ("Q201", "Q301")})


@requires_usd
@pytest.mark.parametrize("settings", [Settings(), FLAG_ALL], ids=["defaults", "flag-all"])
def test_same_findings_as_the_meshes_written_as_obj(tmp_path, settings):
    obj = tmp_path / "scene.obj"
    write_obj(load(SCENE), obj)
    from_usd, from_obj = check_file(str(SCENE), settings), check_file(str(obj), settings)
    assert from_usd.error is None and from_obj.error is None
    assert from_usd.counts == from_obj.counts
    # The two crates reference one Box (</Crate>): the stage reports its faces once, at CrateA's (6, 7);
    # the OBJ has CrateB's copies as faces 8 and 9.
    assert [(e["prim"], e["layer_prim"], e["prims"]) for e in from_usd.shared] == \
        [("/World/CrateA/Box", "/Crate/Box", ["/World/CrateA/Box", "/World/CrateB/Box"])]
    crate_b = [8, 9]
    expected = {code: tuple(zip(*[(f, v) for f, v in zip(*faces_values) if f not in crate_b]))
                for code, faces_values in hits_by_code(from_obj).items()}
    assert {code: tuple(map(tuple, fv)) for code, fv in hits_by_code(from_usd).items()} == expected
    assert len(from_usd.hits) == (3 if settings is not FLAG_ALL else 5)  # Q101-Q103, Q202, Q203


def assert_same_mesh(a, b):
    for name in ("positions", "face_start", "corner_vertex", "texcoords", "corner_texcoord", "normals",
                 "corner_normal", "colors", "face_group", "prim_face_start"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert (a.group_names, a.up_axis, a.meters_per_unit) == (b.group_names, b.up_axis, b.meters_per_unit)


@requires_usd
def test_usdc_and_usdz_read_back_identically(tmp_path):
    from pxr import Usd, UsdUtils

    usdc, usdz = tmp_path / "scene.usdc", tmp_path / "scene.usdz"
    assert Usd.Stage.Open(str(SCENE)).Export(str(usdc))
    assert UsdUtils.CreateNewUsdzPackage(str(usdc), str(usdz))
    expected = load(SCENE)
    for path in (usdc, usdz):
        assert_same_mesh(load(path), expected)


@pytest.mark.parametrize("interpolation, values, indices, expected", [
    ("constant", 1, None, [0] * 7),
    ("uniform", 2, None, [0, 0, 0, 0, 1, 1, 1]),
    ("uniform", 1, [0, 0], [0] * 7),
    ("vertex", 5, None, [0, 1, 2, 3, 1, 4, 2]),
    ("varying", 2, [0, 1, 1, 0, 1], [0, 1, 1, 0, 1, 1, 1]),
    ("faceVarying", 7, None, [0, 1, 2, 3, 4, 5, 6]),
    ("faceVarying", 3, [0, 1, 2, 0, 0, 1, 2], [0, 1, 2, 0, 0, 1, 2]),
])
def test_corner_index_for_every_interpolation(interpolation, values, indices, expected):
    primvar = _Primvar("primvars:st", np.zeros((values, 2)), interpolation,
                       None if indices is None else np.array(indices))
    # A quad 0-1-2-3 and a triangle 1-4-2 on 5 points.
    index = corner_index(primvar, 5, np.array([4, 3]), np.array([0, 1, 2, 3, 1, 4, 2]))
    assert index.tolist() == expected


def test_face_varying_colours_split_only_the_vertices_on_a_colour_seam():
    positions = np.arange(15.0).reshape(5, 3)
    corner_vertex = np.array([0, 1, 2, 3, 1, 4, 2])
    corner_color = np.array([0, 0, 0, 0, 1, 1, 0])  # vertex 1 is red in the quad, blue in the triangle
    colors = np.array([[1.0, 0, 0], [0, 0, 1]])
    new_positions, new_vertex, per_vertex = colors_per_vertex(positions, corner_vertex, corner_color, colors)
    assert len(new_positions) == 6
    np.testing.assert_array_equal(new_positions[new_vertex], positions[corner_vertex])
    np.testing.assert_array_equal(per_vertex[new_vertex], colors[corner_color])


# ---------------------------------------------------------------- bad input

MESH = """#usda 1.0
def Xform "World"
{{
    def Mesh "Bad"
    {{
        point3f[] points = [{points}]
        int[] faceVertexCounts = [{counts}]
        int[] faceVertexIndices = [{indices}]
        {extra}
    }}
}}
"""
GOOD = {"points": "(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)", "counts": "4", "indices": "0, 1, 2, 3", "extra": ""}


def stage_text(**changes) -> str:
    return MESH.format(**{**GOOD, **changes})


BAD_STAGES = {
    "counts-indices": (stage_text(counts="4, 3"),
                       "/World/Bad: faceVertexCounts add up to 7 corners but faceVertexIndices has 4 entries"),
    "index-range": (stage_text(indices="0, 1, 2, 7"),
                    "/World/Bad: faceVertexIndices has an entry outside the 4 points"),
    "two-corners": (stage_text(counts="2, 2"), "/World/Bad: faceVertexCounts has a face with 2 corners"),
    "nan-point": (stage_text(points="(0, 0, 0), (1, 0, 0), (nan, 1, 0), (0, 1, 0)"),
                  "/World/Bad: points has NaN or Inf values"),
    "inf-uv": (stage_text(extra='texCoord2f[] primvars:st = [(0, 0), (1, 0), (inf, 1), (0, 1)] '
                                '(interpolation = "vertex")'), "/World/Bad: primvars:st has NaN or Inf values"),
    "uv-length": (stage_text(extra='texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1)] '
                                   '(interpolation = "faceVarying")'),
                  "/World/Bad: primvars:st has 3 values; faceVarying interpolation needs 4 here"),
    "uv-indices-length": (stage_text(extra='texCoord2f[] primvars:st = [(0, 0)] (interpolation = "faceVarying")\n'
                                           'int[] primvars:st:indices = [0, 0]'),
                          "/World/Bad: primvars:st has 2 indices; faceVarying interpolation needs 4 here"),
    "uv-indices-range": (stage_text(extra='texCoord2f[] primvars:st = [(0, 0)] (interpolation = "vertex")\n'
                                          'int[] primvars:st:indices = [0, 0, 0, 1]'),
                         "/World/Bad: primvars:st:indices has an entry outside the 1 values"),
    "uv-not-2d": (stage_text(extra='float3[] primvars:st = [(0, 0, 0)] (interpolation = "constant")'),
                  "/World/Bad: primvars:st is float3[], not 2-component values"),
    "parse-error": ('#usda 1.0\ndef Mesh "M"\n{\n    int[] faceVertexCounts = [4,\n', "cannot open the stage: "),
}


@requires_usd
@pytest.mark.parametrize("name", BAD_STAGES)
def test_bad_stage_is_one_line_naming_file_and_prim(tmp_path, name):
    text, reason = BAD_STAGES[name]
    path = tmp_path / f"{name}.usda"
    path.write_text(text)
    result = check(str(path))
    assert result.returncode == 2
    assert result.stdout.splitlines()[-1] == "No findings (0 files checked, 1 unreadable)."
    [line] = result.stderr.splitlines()
    assert line.startswith(f"{path}:") and f": Q901 unreadable: {reason}" in line, line


@requires_usd
@pytest.mark.parametrize("content", [b"\x00\x01 not a crate file" * 4, "ñ日本".encode() * 8], ids=["junk", "utf8"])
@pytest.mark.parametrize("suffix", [".usd", ".usdc", ".usdz"])
def test_files_pxr_cannot_open(tmp_path, content, suffix):
    path = tmp_path / f"broken{suffix}"
    path.write_bytes(content)
    result = check(str(path))
    assert result.returncode == 2
    [line] = result.stderr.splitlines()
    assert line.startswith(f"{path}:0: Q901 unreadable: cannot open the stage: ")


@requires_usd
def test_parse_error_points_at_its_line(tmp_path):
    path = tmp_path / "cut.usda"
    path.write_text(BAD_STAGES["parse-error"][0])
    with pytest.raises(MeshError) as caught:
        load(path)
    assert caught.value.line == 5


def test_without_usd_core_a_usd_file_names_the_install_command():
    result = run_without("pxr", "check", str(SCENE), str(ROOT / "affinity" / "data" / "demo"), cwd=ROOT)
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        f"{SCENE}:0: Q901 unreadable: reading USD needs usd-core: pip install 'quad-affinity[usd]'"]
    assert "unreadable" in result.stdout and "Traceback" not in result.stderr  # the OBJ demo files were checked


# ---------------------------------------------------------------- the command line and the formats

@requires_usd
def test_text_output_names_prim_and_face_within_it():
    result = check(str(SCENE))
    assert result.returncode == 1
    assert result.stdout.splitlines()[:3] == [  # errors first, the furthest beyond its threshold first
        f"{SCENE}:/World/Panel:face 1: Q101 error uv-disaffine: {RULES['Q101'].summary}: {assumed_texture_note(1024)} "
        "(175.7 vs 0.5 texels)",
        f"{SCENE}:/World/Panel:face 0: Q102 error color-disaffine: {RULES['Q102'].summary} (127.5 vs 2/255)",
        f"{SCENE}:/World/Panel:face 1: Q103 warning normal-disaffine: {RULES['Q103'].summary} (6.525 vs 2 degrees)",
    ]
    assert result.stderr.splitlines() == [f"{SCENE}: note: {note}" for note in load(SCENE).notes]


@requires_usd
def test_time_and_uv_primvar_flags():
    later = check("--time", "5", "-q", str(SCENE))
    assert f"{SCENE}:/World/Animated:face 0: Q101 error uv-disaffine" in later.stdout
    assert check("--uv-primvar", "map1", "--select", "Q101", "-q", str(SCENE)).returncode == 0
    assert check("--time", "soon", str(SCENE)).returncode == 2


@requires_usd
def test_usd_options_reach_the_worker_processes():
    tasks = [(str(SCENE), Settings())] * 2
    for report in check_files(tasks, jobs=2, usd=UsdOptions(time=5)):
        assert 5 in hits_by_code(report)["Q101"][0]  # /World/Animated's quad, flagged at time 5 only


@requires_usd
def test_json_carries_prim_and_stage_metadata():
    doc = json.loads(check("--format", "json", str(SCENE)).stdout)
    [entry] = doc["files"]
    assert (entry["up_axis"], entry["meters_per_unit"], entry["faces"]) == ("Z", 0.01, 11)
    assert len(entry["notes"]) == 3  # hidden prims, the PointInstancer, the subdivision surfaces
    first = doc["findings"][0]
    assert {k: first[k] for k in ("line", "column", "face", "prim", "group", "code")} == {
        "line": 0, "column": 0, "face": 0, "prim": "/World/Panel", "group": "/World/Panel", "code": "Q102"}


@requires_usd
def test_sarif_locates_by_prim_without_a_region():
    log = json.loads(check("--format", "sarif", str(SCENE)).stdout)
    assert_valid(log)
    result = log["runs"][0]["results"][1]
    [location] = result["locations"]
    assert "region" not in location["physicalLocation"]
    assert location["logicalLocations"] == [{"name": "Panel", "fullyQualifiedName": "/World/Panel", "kind": "object"}]
    assert result["properties"]["prim"] == "/World/Panel" and result["properties"]["face"] == 1
    assert result["message"]["text"].endswith(", /World/Panel face 1")


@requires_usd
def test_github_and_junit_name_the_prim():
    github = check("--format", "github", str(SCENE)).stdout.splitlines()
    (colour,) = [line for line in github if "title=Q102" in line]
    # 127.5/255 is far past the 8/255 visibility threshold: an error
    assert colour.startswith(f"::error file={SCENE.relative_to(ROOT)},title=Q102 color-disaffine::")
    assert colour.endswith(", /World/Panel face 0")
    junit = check("--format", "junit", str(SCENE)).stdout
    assert 'name="Q102 color-disaffine /World/Panel face 0"' in junit
    assert "/World/Panel:face 0: Q102 error color-disaffine:" in junit  # the text line names the prim


def test_directories_and_the_hook_include_usd_files(tmp_path):
    for name in ("a.usd", "b.USDA", "c.usdc", "d.usdz", "e.txt"):
        (tmp_path / name).write_bytes(b"")
    assert [Path(p).name for p in collect_paths([str(tmp_path)])] == ["a.usd", "b.USDA", "c.usdc", "d.usdz"]
    assert {".usd", ".usda", ".usdc", ".usdz"} <= set(MESH_SUFFIXES)
    hook = (ROOT / ".pre-commit-hooks.yaml").read_text()
    pattern = re.search(r"^\s*files: (.+)$", hook, re.MULTILINE).group(1)
    assert all(re.search(pattern, f"assets/x.{ext}") for ext in ("obj", "usd", "usda", "USDC", "usdz"))
