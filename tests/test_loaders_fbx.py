"""FBX in (issue 59): Blender's exports of the shared meshes read as their OBJ files are read, the scene's
nodes as groups, uv sets by name, textures by role (beside the file and embedded in it), and bad input as
one Q901 line.

The FBX files in tests/data/fbx were written by Blender from the shared OBJ meshes
(tests/data/fbx/make_fbx.py): a second implementation of the mesh model, whose
exporter keeps polygon order and corner order. Synthetic files come from the small
writer in tests/helpers/fbx_binary.py, for what Blender never writes.
"""

from __future__ import annotations

import ctypes
import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import run, run_without
from helpers.fbx_binary import MeshNode, scene_bytes

from affinity.errors import MeshError
from affinity.loaders import load
from affinity.loaders.formats import LOADERS, described
from affinity.loaders.isolated import read_isolated
from affinity.loaders.usd import UsdOptions
from affinity.pipeline.check import check_file
from affinity.settings import Settings

pytest.importorskip("ufbx", reason="needs the fbx extra (ufbx)")

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "fbx"
#: The shared meshes Blender exported (tests/data/fbx/make_fbx.py: every one of them).
MESHES = ("spot_control_mesh", "makehuman_base_hm08", "gen_spot_cc4", "gen_uv_sphere_64x32", "gen_vase_revolution",
          "osd_catmark_bishop", "osd_catmark_car", "osd_catmark_nonquads", "osd_catmark_torus",
          "tinyobjloader_cube_vertexcol")
#: Blender holds positions and uv in float32; the OBJ files' six decimals are read in float64.
FLOAT32 = 2e-6


def corner_values(mesh, name: str) -> np.ndarray:
    """(C, K) the attribute at every corner, in file order."""
    every = np.arange(len(mesh.corner_vertex))[:, None]
    return mesh.corner_attribute(name, every)[:, 0]


def findings(report) -> dict[tuple[str, int], float]:
    """(code, face in file order) -> value of a checked file's findings."""
    return {(h.code, int(face)): float(value) for h in report.hits for face, value in zip(h.faces, h.values)}


@pytest.mark.parametrize("name", MESHES)
def test_blender_export_keeps_every_polygon_and_its_corner_order(name, shared_meshes):
    obj, fbx = load(shared_meshes / f"{name}.obj"), load(DATA / f"{name}.fbx")
    assert fbx.counts() == obj.counts()
    np.testing.assert_array_equal(fbx.face_start, obj.face_start)
    scale = np.abs(obj.positions).max()
    np.testing.assert_allclose(corner_values(fbx, "positions"), corner_values(obj, "positions"),
                               rtol=0, atol=FLOAT32 * scale)  # corner k of face f is the OBJ's corner k
    if obj.texcoords is not None:
        np.testing.assert_allclose(corner_values(fbx, "texcoords"), corner_values(obj, "texcoords"), rtol=0,
                                   atol=FLOAT32 * max(1.0, np.abs(obj.texcoords).max()))
    assert fbx.group_names == [f"/{name}"] and fbx.prim_face_start.tolist() == [0, obj.n_faces]
    assert fbx.up_axis == "Y" and fbx.meters_per_unit == 1.0  # Blender's defaults: Y up, a metre a unit


@pytest.mark.parametrize("name", MESHES)
def test_blender_export_gives_the_findings_of_its_obj(name, shared_meshes):
    obj = check_file(str(shared_meshes / f"{name}.obj"), Settings())
    fbx = check_file(str(DATA / f"{name}.fbx"), Settings())
    assert fbx.error is None and fbx.counts == obj.counts
    got, want = findings(fbx), findings(obj)
    renormalled = faces_blender_renormalled(load(shared_meshes / f"{name}.obj"), load(DATA / f"{name}.fbx"))
    got, want = ({key: value for key, value in table.items() if not (key[0] == "Q103" and key[1] in renormalled)}
                 for table in (got, want))
    assert set(got) == set(want)
    for key, value in want.items():  # float32 positions move a value by a fraction of a percent at most
        assert got[key] == pytest.approx(value, rel=1e-2, abs=1e-3), key


def faces_blender_renormalled(obj, fbx) -> set[int]:
    """The faces whose corner normals Blender wrote differently from the OBJ's (every face of an OBJ without
    normals: Blender writes those it computed; the zero-area pole quads of the uv sphere, where it recomputes
    them): Q103 is measured on other normals there."""
    if obj.normals is None:
        return set(range(obj.n_faces))
    moved = np.abs(corner_values(fbx, "normals") - corner_values(obj, "normals")).max(axis=1) > 1e-3
    return set(np.repeat(np.arange(obj.n_faces), obj.face_sizes)[moved].tolist())


def q101_levels(report) -> dict[int, str]:
    return {int(face): level for h in report.hits if h.code == "Q101"
            for face, level in zip(h.faces, h.levels())} if report.hits else {}


@pytest.mark.parametrize("export", ["external", "embedded"])
def test_textured_spot_reads_its_texture_with_the_levels_of_its_obj(export, shared_meshes, tmp_path):
    obj = check_file(str(shared_meshes / "textured" / "spot_control_mesh_textured.obj"), Settings())
    source = DATA / f"spot_textured_{export}.fbx"
    if export == "embedded":  # alone in a folder: the image can only come from inside the file
        shutil.copy(source, tmp_path / source.name)
        source = tmp_path / source.name
        assert not list(tmp_path.glob("*.fbm")) and not list(tmp_path.glob("*.png"))
    fbx = check_file(str(source), Settings())
    assert fbx.error is None
    levels, want = q101_levels(fbx), q101_levels(obj)
    assert levels == want and "error" in set(want.values())
    (got_hits,) = [h for h in fbx.hits if h.code == "Q101"]
    (want_hits,) = [h for h in obj.hits if h.code == "Q101"]
    assert got_hits.visible is not None and got_hits.visible.roles == ["base colour"]
    np.testing.assert_allclose(got_hits.visible.values, want_hits.visible.values, rtol=2e-2, atol=0.5)


def test_instances_of_one_geometry_are_reported_once_with_every_node_path():
    result = run("check", "--isolated", "--no-cache", "--format", "json", str(DATA / "spot_instanced.fbx"))
    single = run("check", "--isolated", "--no-cache", "--format", "json", str(DATA / "spot_control_mesh.fbx"))
    document, alone = json.loads(result.stdout), json.loads(single.stdout)
    assert document["files"][0]["faces"] == 2 * alone["files"][0]["faces"]
    # the copy is moved, turned and scaled uniformly: the same findings, once, at the first node
    assert [(f["code"], f["face"]) for f in document["findings"]] == \
        [(f["code"], f["face"]) for f in alone["findings"]]
    assert {f["prim"] for f in document["findings"]} == {"/Root/Body"}
    assert {tuple(f["prims"]) for f in document["findings"]} == {("/Root/Body", "/Root/Copy")}


def test_text_lines_and_sarif_locate_a_face_by_node_path():
    path = DATA / "spot_instanced.fbx"
    text = run("check", "--isolated", "--no-cache", "--select", "Q204", str(path))
    assert text.returncode == 1
    assert text.stdout.splitlines()[0].startswith(f"{path}:/Root/Body:face 60: Q204 error bowtie-quad")
    sarif = json.loads(run("check", "--isolated", "--no-cache", "--select", "Q204", "--format", "sarif",
                           str(path)).stdout)
    names = [[place["fullyQualifiedName"] for place in result["locations"][0]["logicalLocations"]]
             for result in sarif["runs"][0]["results"]]
    assert names and all(found == ["/Root/Body", "/Root/Copy"] for found in names)


def test_uv_primvar_picks_a_uv_set_by_its_fbx_name():
    path = DATA / "spot_two_uv_sets.fbx"
    first, planar = load(path), load(path, UsdOptions(uv_primvar="Planar"))
    spot = load(DATA / "spot_control_mesh.fbx")
    np.testing.assert_array_equal(corner_values(first, "texcoords"), corner_values(spot, "texcoords"))
    # make_fbx.py wrote the mesh's own x and y (Blender's importer turns the object, not its vertices)
    np.testing.assert_allclose(corner_values(planar, "texcoords"), corner_values(planar, "positions")[:, :2],
                               atol=1e-6)
    missing = run("check", "--isolated", "--no-cache", "--uv-primvar", "Nope", "--format", "json", str(path))
    document = json.loads(missing.stdout)
    assert not [f for f in document["findings"] if f["code"] in ("Q101", "Q301", "Q302")]
    assert document["files"][0]["notes"] == ["no mesh has the uv set 'Nope': texture coordinates not checked"]


def test_the_result_cache_tells_uv_sets_apart(tmp_path, monkeypatch):
    path = DATA / "spot_two_uv_sets.fbx"
    monkeypatch.setenv("AFFINITY_CACHE_DIR", str(tmp_path))
    counts = []
    for extra in ([], ["--uv-primvar", "Planar"], []):
        result = run("check", "--isolated", "--format", "json", *extra, str(path))
        counts.append(sum(f["code"] == "Q302" for f in json.loads(result.stdout)["findings"]))
    assert counts[0] == counts[2] == 3 and counts[1] > 3


# ---------------------------------------------------------------- synthetic scenes: what Blender never writes

SQUARE_AND_TRIANGLE = (np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0.5]], dtype=float),
                       np.array([0, 4, 7]), np.array([0, 1, 2, 3, 1, 4, 2]))


def write(tmp_path: Path, meshes, name="scene.fbx", **scene) -> Path:
    path = tmp_path / name
    path.write_bytes(scene_bytes(meshes, **scene))
    return path


def test_every_layer_mapping_reads_as_the_values_it_names(tmp_path):
    points, face_start, corners = SQUARE_AND_TRIANGLE
    by_corner = np.arange(14, dtype=float).reshape(7, 2) / 10
    mesh = MeshNode("A", points, face_start, corners,
                    uv=[("First", "ByPolygonVertex", "IndexToDirect", by_corner[::-1], np.arange(7)[::-1]),
                        ("Second", "ByVertice", "Direct", points[:, :2] * 2, None)],
                    normals=("", "ByPolygon", "Direct", np.array([[0, 0, 2.0], [0, 1, 1]]), None),
                    colors=("", "AllSame", "Direct", np.array([[1, 0.5, 0, 1.0]]), None),
                    materials=["wood", "steel"], face_slots=np.array([1, 0]))
    read = load(write(tmp_path, [mesh], up_axis=2, unit_cm=2.54))
    read.validate()
    np.testing.assert_allclose(corner_values(read, "texcoords"), by_corner)
    np.testing.assert_allclose(corner_values(read, "normals"),
                               [[0, 0, 1]] * 4 + [[0, 2 ** -0.5, 2 ** -0.5]] * 3)
    np.testing.assert_allclose(corner_values(read, "colors"), [[1, 0.5, 0]] * 7)
    assert read.material_names == ["wood", "steel"] and read.face_material.tolist() == [1, 0]
    assert (read.up_axis, read.meters_per_unit) == ("Z", pytest.approx(0.0254))
    second = load(tmp_path / "scene.fbx", UsdOptions(uv_primvar="Second"))
    np.testing.assert_allclose(corner_values(second, "texcoords"), points[corners, :2] * 2)


def test_nodes_are_placed_in_world_space_and_named_by_their_path(tmp_path):
    points, face_start, corners = SQUARE_AND_TRIANGLE
    meshes = [MeshNode("Body", points, face_start, corners, translation=(1.0, 2.0, 3.0)),
              MeshNode("Arm", points, face_start, corners, translation=(10.0, 0.0, 0.0), geometry=0)]
    read = load(write(tmp_path, meshes, parents=[None, 0]))
    assert read.group_names == ["/Body", "/Body/Arm"] and read.prim_face_start.tolist() == [0, 2, 4]
    np.testing.assert_allclose(read.positions[read.corner_vertex[:7]], points[corners] + [1, 2, 3])
    np.testing.assert_allclose(read.positions[read.corner_vertex[7:]], points[corners] + [11, 2, 3])
    assert read.prim_sources[0] == read.prim_sources[1]  # one geometry


@pytest.mark.parametrize("face_start, corners, reason", [
    ([0, 4, 7], [0, 1, 99, 3, 1, 4, 2], "not a readable FBX file (UnknownError: Failed to load)"),  # ufbx says no more
    ([0, 4], [0, 1, 2, 3, 1, 4, 2], "/A: PolygonVertexIndex does not end its last polygon"),
    ([0, 4, 6], [0, 1, 2, 3, 1, 4], "/A: polygon 1 has 2 corners (at least 3 needed)"),
])
def test_hostile_topology_is_one_clear_reason(face_start, corners, reason, tmp_path):
    points = SQUARE_AND_TRIANGLE[0]
    with pytest.raises(MeshError) as caught:
        load(write(tmp_path, [MeshNode("A", points, np.array(face_start), np.array(corners))]))
    assert (caught.value.line, caught.value.reason) == (0, reason)


def test_a_uv_index_outside_its_values_makes_the_file_unreadable(tmp_path):
    points, face_start, corners = SQUARE_AND_TRIANGLE
    mesh = MeshNode("A", points, face_start, corners,
                    uv=[("UVMap", "ByPolygonVertex", "IndexToDirect", points[:, :2],
                         np.array([0, 1, 2, 3, 1, 40, 2]))])
    with pytest.raises(MeshError) as caught:
        load(write(tmp_path, [mesh]))
    assert caught.value.reason == "not a readable FBX file (BadIndexError: Bad index: 40 (max 4))"


# ---------------------------------------------------------------- bad files, the missing extra, fix

def test_truncated_and_junk_files_are_one_q901_line_each_and_the_others_are_checked(tmp_path):
    whole = (DATA / "spot_control_mesh.fbx").read_bytes()
    cut = tmp_path / "cut.fbx"
    cut.write_bytes(whole[: len(whole) // 3])
    junk = tmp_path / "junk.fbx"
    junk.write_bytes(b"not an FBX file at all\n")
    good = tmp_path / "good.fbx"
    good.write_bytes(whole)
    result = run("check", "--isolated", "--no-cache", str(cut), str(junk), str(good))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 2 and lines[0].startswith(f"{cut}:0: Q901 unreadable: not a readable FBX file (")
    assert lines[1].startswith(f"{junk}:0: Q901 unreadable: not a readable FBX file (")
    assert f"{good}:/spot_control_mesh:face " in result.stdout


def _crash() -> None:
    ctypes.string_at(0)  # reads address 0: a segmentation fault, as a native reader's bug would be


def _allocate() -> bytes:
    return bytearray(64 << 40)  # 64 TiB: over any limit


def test_a_crash_of_the_reader_costs_its_file_only(tmp_path):
    path = tmp_path / "x.fbx"
    path.write_bytes(b"x")
    with pytest.raises(MeshError) as caught:
        read_isolated(str(path), _crash)
    assert caught.value.reason == "the reader stopped without an answer (killed by SIGSEGV)"
    with pytest.raises(MeshError) as caught:
        read_isolated(str(path), _allocate)
    assert caught.value.reason == "the reader ran out of memory"
    assert read_isolated(str(path), np.arange, 5).tolist() == [0, 1, 2, 3, 4]  # and an answer comes back


def test_without_ufbx_an_fbx_file_names_the_extra():
    fbx = DATA / "spot_control_mesh.fbx"
    result = run_without("ufbx", "check", "--no-cache", str(fbx), str(ROOT / "affinity" / "data" / "demo"), cwd=ROOT)
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        f"{fbx}:0: Q901 unreadable: reading FBX needs ufbx: pip install 'quad-affinity[fbx]'"]
    assert "checked" in result.stdout and "Traceback" not in result.stderr  # the OBJ demo files were checked


def test_fix_leaves_an_fbx_file_untouched_and_names_the_way_out(tmp_path):
    path = tmp_path / "spot.fbx"
    shutil.copy(DATA / "spot_control_mesh.fbx", path)
    before = path.read_bytes()
    result = run("fix", "--isolated", str(path))
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        f"{path}: FBX is not written (no FBX writer exists on PyPI): export OBJ or USD from the DCC tool, "
        "fix that, and re-export"]
    assert path.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["spot.fbx"]


def test_the_format_table_names_fbx_and_its_extra():
    assert LOADERS[".fbx"].extra == "fbx" and LOADERS[".fbx"].scene
    assert described().endswith("and FBX (.fbx, with the fbx extra)")


def test_a_scene_without_a_mesh_is_skipped_as_a_usd_look_layer_is(tmp_path):
    path = write(tmp_path, [], name="rig.fbx")  # an animation or a camera rig: nothing to check
    result = run("check", "--isolated", "--no-cache", str(path))
    assert result.returncode == 0 and result.stderr.splitlines() == [f"{path}: skipped (no-mesh)"]


def test_the_result_cache_sees_a_texture_the_fbx_file_names_change(tmp_path, monkeypatch):
    from PIL import Image

    shutil.copytree(DATA / "spot_textured_external.fbm", tmp_path / "spot_textured_external.fbm")
    path = tmp_path / "spot.fbx"
    shutil.copy(DATA / "spot_textured_external.fbx", path)
    monkeypatch.setenv("AFFINITY_CACHE_DIR", str(tmp_path / "cache"))

    def errors() -> int:
        result = run("check", "--isolated", "--select", "Q101", "--format", "json", str(path))
        return sum(f["level"] == "error" for f in json.loads(result.stdout)["findings"])

    assert errors() > 0
    texture = tmp_path / "spot_textured_external.fbm" / "spot_texture.png"
    texture.chmod(0o644)
    Image.new("RGB", Image.open(texture).size, (128, 128, 128)).save(texture)  # flat: no crease can show
    assert errors() == 0


def test_an_embedded_image_is_the_mesh_s_texture_for_drawing_too(tmp_path, shared_meshes):
    from PIL import Image

    from affinity.draw.texture import load_image, painted_texture

    shutil.copy(DATA / "spot_textured_embedded.fbx", tmp_path / "spot.fbx")
    mesh = load(tmp_path / "spot.fbx")
    path = painted_texture(mesh)
    assert path == f"{tmp_path / 'spot.fbx'}#spot_textured_embedded.fbm/spot_texture.png" and not os.path.exists(path)
    drawn = load_image(path)
    with Image.open(shared_meshes / "textured" / "spot_texture.png") as image:
        png = np.asarray(image.convert("RGB"), dtype=np.float32) / 255
    np.testing.assert_allclose(drawn, png, atol=1e-6)


def _hang() -> None:
    import time

    time.sleep(60)  # neither works nor ends, as a child deadlocked on a lock would


def test_a_reader_that_neither_works_nor_ends_is_stopped(tmp_path, monkeypatch):
    import affinity.loaders.isolated as isolated

    path = tmp_path / "x.fbx"
    path.write_bytes(b"x")
    monkeypatch.setattr(isolated, "WALL_FACTOR", 0.05)  # 1.5 s for a file of one byte
    with pytest.raises(MeshError) as caught:
        read_isolated(str(path), _hang)
    assert caught.value.reason == "the reader stopped without an answer (killed by SIGKILL)"


def test_a_texture_is_found_as_fbx_stores_it_relative_then_absolute_then_embedded(tmp_path):
    from types import SimpleNamespace

    from affinity.loaders.fbxmaterials import texture_file

    fbx = tmp_path / "scene" / "model.fbx"
    (tmp_path / "scene" / "maps").mkdir(parents=True)
    beside, elsewhere = tmp_path / "scene" / "maps" / "wood.png", tmp_path / "wood_absolute.png"
    beside.write_bytes(b"png")
    elsewhere.write_bytes(b"png")
    texture = lambda relative, absolute, content=b"": SimpleNamespace(
        relative_filename=relative, absolute_filename=absolute, content=content, name="Wood")
    assert texture_file(texture("maps/wood.png", str(elsewhere)), str(fbx)) == (str(beside), "maps/wood.png", None)
    assert texture_file(texture("gone/wood.png", str(elsewhere)), str(fbx)) == \
        (str(elsewhere), "gone/wood.png", None)
    assert texture_file(texture("gone/wood.png", "/nowhere/wood.png", b"\x89PNG"), str(fbx)) == \
        (f"{fbx}#gone/wood.png", "gone/wood.png", b"\x89PNG")
    assert texture_file(texture("gone/wood.png", "/nowhere/wood.png"), str(fbx)) == \
        (str(tmp_path / "scene" / "gone" / "wood.png"), "gone/wood.png", None)  # missing: the reading says so


def test_material_properties_bind_their_textures_by_role(tmp_path):
    from types import SimpleNamespace

    from affinity.loaders.fbxmaterials import material_maps

    fbx = tmp_path / "model.fbx"
    for name in ("base.png", "normal.png", "bump.png", "rough.png", "other_uv.png"):
        (tmp_path / name).write_bytes(b"png")

    def bound(prop: str, file: str, uv_set: str = "") -> SimpleNamespace:
        texture = SimpleNamespace(relative_filename=file, absolute_filename="", content=b"", name=file,
                                  uv_set=uv_set, file_textures=[], has_uv_transform=False)
        return SimpleNamespace(material_prop=prop, texture=texture)

    material = SimpleNamespace(name="M", textures=[
        bound("DiffuseColor", "base.png"), bound("NormalMap", "normal.png"), bound("Bump", "bump.png"),
        bound("Maya|specularRoughness", "rough.png"), bound("DiffuseColor", "other_uv.png", uv_set="Lightmap")])
    maps, embedded = material_maps(material, str(fbx), "UVMap")
    assert [(m.role, os.path.basename(m.path)) for m in maps] == [
        ("base colour", "base.png"), ("normal", "normal.png"), ("height", "bump.png"), ("scalar", "rough.png")]
    assert embedded == {} and maps[0].source == "FBX M.DiffuseColor"


@pytest.mark.parametrize("values, reason", [
    (5, "not a readable FBX file (BadIndexError: Bad index: 5 (max 4))"),  # ufbx stops it first
    (8, "/A: LayerElementUV UV (ByPolygonVertex) has 8 values; faceVarying interpolation needs 7 here"),
])
def test_a_direct_layer_with_the_wrong_number_of_values_is_one_clear_reason(values, reason, tmp_path):
    points, face_start, corners = SQUARE_AND_TRIANGLE
    uv = np.arange(2 * values, dtype=float).reshape(values, 2)
    mesh = MeshNode("A", points, face_start, corners, uv=[("UVMap", "ByPolygonVertex", "Direct", uv, None)])
    with pytest.raises(MeshError) as caught:
        load(write(tmp_path, [mesh]))
    assert caught.value.reason == reason


def test_float32_vertices_and_int64_indices_read_as_the_values_written(tmp_path):
    points, face_start, corners = SQUARE_AND_TRIANGLE
    points = points + 0.1  # not exact in float32
    mesh = MeshNode("A", points, face_start, corners, vertex_dtype=np.float32, index_dtype=np.int64)
    read = load(write(tmp_path, [mesh]))
    np.testing.assert_array_equal(read.positions[read.corner_vertex], points.astype(np.float32)[corners])
    np.testing.assert_array_equal(read.face_start, face_start)


ASCII_QUAD_AND_TRIANGLE = """\
; FBX 7.4.0 project file
FBXHeaderExtension:  {
    FBXHeaderVersion: 1003
    FBXVersion: 7400
}
GlobalSettings:  {
    Version: 1000
    Properties70:  {
        P: "UpAxis", "int", "Integer", "",2
        P: "UnitScaleFactor", "double", "Number", "",1
    }
}
Objects:  {
    Geometry: 1000, "Geometry::quad", "Mesh" {
        Vertices: *15 {
            a: 0,0,0,1,0,0,1,1,0,0,1,0,2,0,0.5
        }
        PolygonVertexIndex: *7 {
            a: 0,1,2,-4,1,4,-3
        }
        LayerElementUV: 0 {
            Version: 101
            Name: "UVMap"
            MappingInformationType: "ByPolygonVertex"
            ReferenceInformationType: "IndexToDirect"
            UV: *10 {
                a: 0,0,1,0,1,1,0,1,2,0
            }
            UVIndex: *7 {
                a: 0,1,2,3,1,4,2
            }
        }
    }
    Model: 2000, "Model::quad", "Mesh" {
        Version: 232
    }
}
Connections:  {
    C: "OO",1000,2000
    C: "OO",2000,0
}
"""


def test_an_ascii_fbx_reads_as_the_binary_one(tmp_path):
    path = tmp_path / "ascii.fbx"
    path.write_text(ASCII_QUAD_AND_TRIANGLE)
    points, face_start, corners = SQUARE_AND_TRIANGLE
    uv = ("UVMap", "ByPolygonVertex", "IndexToDirect", points[:, :2], corners)
    binary = load(write(tmp_path, [MeshNode("quad", points, face_start, corners, uv=[uv])], up_axis=2, unit_cm=1.0))
    read = load(path)
    assert (read.group_names, read.up_axis, read.meters_per_unit) == (["/quad"], "Z", 0.01)
    for name in ("positions", "texcoords"):
        np.testing.assert_array_equal(corner_values(read, name), corner_values(binary, name))
    np.testing.assert_array_equal(read.face_start, binary.face_start)
