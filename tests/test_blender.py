"""affinity.blender inside headless Blender (the ``bpy`` wheel); skipped where bpy is not installed.

CI runs this file in a venv of its own (bpy pins NumPy < 2, see .ci/run). bpy is
one Blender session per process: every test starts from an empty factory scene.
"""

from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest
from helpers.blender_cli import run_cli_json
from helpers.blender_scenes import (
    base_color_material,
    empty_scene,  # noqa: F401 (autouse: every test in an empty scene)
    mesh_object,
)

bpy = pytest.importorskip("bpy")

from affinity.blender import addon, findings, mesh_from_object  # noqa: E402
from affinity.blender.check import check_object  # noqa: E402
from affinity.blender.convert import ERROR_ATTRIBUTE, ERROR_COLOR, ORIGINAL_FACE  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def uv_sphere(segments=16, rings=8):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=rings)
    return bpy.context.object


def clear_selection(obj):
    """A new primitive starts fully selected: deselect its vertices, edges and faces."""
    mesh = obj.data
    for items in (mesh.vertices, mesh.edges, mesh.polygons):
        items.foreach_set("select", np.zeros(len(items), dtype=bool))
    mesh.update()


def selected_faces(obj) -> set[int]:
    if bpy.context.mode != "OBJECT":
        bpy.ops.object.mode_set(mode="OBJECT")
    mask = np.zeros(len(obj.data.polygons), dtype=bool)
    obj.data.polygons.foreach_get("select", mask)
    return set(np.flatnonzero(mask).tolist())


def textured(obj, image_path: Path, size=(512, 256)):
    """Give ``obj`` a material whose Base Color is an Image Texture of a saved PNG."""
    image = bpy.data.images.new("checker", size[0], size[1], alpha=False)
    image.generated_type = "COLOR_GRID"
    image.filepath_raw = str(image_path)
    image.file_format = "PNG"
    image.save()
    return base_color_material(obj, image, "Checker")


def by_code_and_face(rows) -> dict[tuple[str, int], float]:
    """Each finding's texel shift: Q101's value, or its ``shift`` where the visible reading read C."""
    return {(r["code"], r["face"]): r.get("shift", r["value"]) for r in rows}


def test_uv_sphere_gives_the_same_findings_as_its_obj_export_checked_by_the_cli(tmp_path):
    sphere = uv_sphere()
    textured(sphere, tmp_path / "checker.png")
    exported = tmp_path / "export" / "sphere.obj"
    exported.parent.mkdir()
    bpy.ops.wm.obj_export(filepath=str(exported), path_mode="COPY", export_materials=True)
    assert (exported.parent / "checker.png").is_file()

    rows = findings(sphere)
    in_memory = by_code_and_face(rows)
    document = run_cli_json("check", str(exported))
    assert set(document["findings"][0]) <= set(rows[0])  # every key of a JSON finding, and more
    # The checker beside the export decodes on both sides: Q101 is read through it (C, design.md's visible
    # reading), the texel shift kept as "shift", and the levels are C's, as the CLI says.
    assert rows[0]["group"] == sphere.name
    assert {r["unit"] for r in rows} == {f["unit"] for f in document["findings"]}
    assert {r["unit"] for r in rows} == {"1/255"} and all("shift" in r for r in rows)
    assert ({(r["face"], r["level"]) for r in rows}
            == {(f["face"], f["level"]) for f in document["findings"]})
    on_file = by_code_and_face(document["findings"])
    assert document["files"][0]["faces"] == len(sphere.data.polygons)
    assert {code for code, _ in in_memory} == {"Q101"}
    assert in_memory.keys() == on_file.keys()
    faces = sorted(face for _, face in in_memory)
    values = np.array([in_memory["Q101", f] for f in faces])
    # The OBJ stores 6 decimals; Blender float32. The 512 x 256 image sets the unit on both sides.
    np.testing.assert_allclose(values, [on_file["Q101", f] for f in faces], rtol=1e-4)
    # Lat-long quads are trapezoids carrying rectangles of uv: flagged; the pole triangles never are.
    sizes = np.array([p.loop_total for p in sphere.data.polygons])
    assert set(np.flatnonzero(sizes == 3).tolist()).isdisjoint(faces)


def test_texel_unit_follows_the_base_color_image(tmp_path):
    sphere = uv_sphere()
    at_default = {r["face"]: r["value"] for r in findings(sphere, select=["Q101"], thresholds={"Q101": 0})}
    textured(sphere, tmp_path / "checker.png", size=(256, 256))
    # Through the image Q101's value is the visible reading; the texel shift it measures is kept as "shift".
    at_256 = {r["face"]: r.get("shift", r["value"]) for r in findings(sphere, select=["Q101"],
                                                                       thresholds={"Q101": 0})}
    assert at_default.keys() == at_256.keys()
    faces = sorted(at_default)
    np.testing.assert_allclose([at_256[f] for f in faces], [at_default[f] / 4 for f in faces], rtol=1e-9)


def test_panel_names_the_texture_that_sets_the_texel_unit(tmp_path):
    sphere = uv_sphere()
    props = bpy.context.scene.affinity
    assert addon.texture_line(sphere, props) == "Texture size: 1024 px (no image)"
    props.texture_size = 300
    assert addon.texture_line(sphere, props) == "Texture size: 300 px (set here)"
    textured(sphere, tmp_path / "checker.png")
    # As on the command line, the image's own size wins over the size set (which counts where none is read).
    assert addon.texture_line(sphere, props) == "Texture: checker 512 x 256 px (read by Blender)"


def test_world_matrix_is_applied():
    bpy.ops.mesh.primitive_plane_add(size=2, location=(1, 2, 3))
    plane = bpy.context.object
    plane.scale = (3, 1, 1)
    bpy.context.view_layer.update()
    mesh = mesh_from_object(plane)
    local = np.array([v.co[:] for v in plane.data.vertices])
    np.testing.assert_allclose(mesh.positions, local * [3, 1, 1] + [1, 2, 3], atol=1e-6)
    assert mesh.group_names == [plane.name] and mesh.counts()["quads"] == 1


@pytest.mark.parametrize(
    ("corner_colors", "flagged"),
    [
        # The Q102 rule page: blue, red, green, black crease; blue, red, yellow, cyan are affine.
        ([(0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 0, 0)], True),
        ([(0, 0, 1), (1, 0, 0), (1, 1, 0), (0, 1, 1)], False),
    ],
)
def test_corner_colour_attribute_is_linted(corner_colors, flagged):
    bpy.ops.mesh.primitive_plane_add(size=1)
    plane = bpy.context.object
    paint_corners(plane, corner_colors)
    codes = {r["code"] for r in findings(plane)}
    assert ("Q102" in codes) is flagged


def paint_corners(plane, corner_colors):
    """A corner colour attribute on the unit plane: ``corner_colors`` at (0,0) (1,0) (1,1) (0,1)."""
    color = plane.data.color_attributes.new("Col", "BYTE_COLOR", "CORNER")
    plane.data.color_attributes.active_color = color
    order = {(-1, -1): 0, (1, -1): 1, (1, 1): 2, (-1, 1): 3}
    rgba = []
    for loop in plane.data.loops:
        co = plane.data.vertices[loop.vertex_index].co
        rgba.extend([*corner_colors[order[int(np.sign(co.x)), int(np.sign(co.y))]], 1.0])
    color.data.foreach_set("color_srgb", rgba)


def tilt_one_corner_normal(plane):
    """Custom split normals on the plane: the first corner's tilted 40 degrees, the others straight up."""
    tilted = np.array([np.sin(np.radians(40)), 0, np.cos(np.radians(40))])
    plane.data.normals_split_custom_set([tilted if i == 0 else np.array([0, 0, 1.0])
                                         for i in range(len(plane.data.loops))])


def test_custom_split_normals_are_linted():
    bpy.ops.mesh.primitive_plane_add(size=1)
    plane = bpy.context.object
    assert "Q103" not in {r["code"] for r in findings(plane)}
    tilt_one_corner_normal(plane)
    assert plane.data.has_custom_normals
    q103 = [r for r in findings(plane) if r["code"] == "Q103"]
    assert [r["face"] for r in q103] == [0] and q103[0]["unit"] == "degrees"


def test_every_attributes_row_reads_in_the_attribute_registrys_unit():
    from affinity.attributes import ATTRIBUTES
    from affinity.rules import RULES

    bpy.ops.mesh.primitive_plane_add(size=1)
    plane = bpy.context.object
    paint_corners(plane, [(0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 0, 0)])  # creases: the Q102 page's square
    tilt_one_corner_normal(plane)
    plane.data.uv_layers[0].data.foreach_set("uv", [0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.0, 1.0])  # not affine
    expected = {r["code"]: (r["value"], r["unit"]) for r in findings(plane)}
    assert bpy.ops.affinity.check() == {"FINISHED"}
    rows = bpy.context.scene.affinity.results
    assert {RULES[row.code].attribute for row in rows} == set(ATTRIBUTES)
    for row in rows:
        unit = ATTRIBUTES[RULES[row.code].attribute].unit
        assert row.unit == unit == expected[row.code][1]
        assert row.worst == pytest.approx(expected[row.code][0], rel=1e-6)
        assert addon.worst_text(row).endswith("/255" if unit == "1/255" else f" {unit}")


def test_check_operator_selects_exactly_the_flagged_faces():
    sphere = uv_sphere()
    clear_selection(sphere)
    expected = {r["face"] for r in findings(sphere) if r["code"] == "Q101"}
    assert 0 < len(expected) < len(sphere.data.polygons)
    assert bpy.ops.affinity.check() == {"FINISHED"}
    rows = bpy.context.scene.affinity.results
    assert [(r.code, r.count) for r in rows] == [("Q101", len(expected))]
    assert selected_faces(sphere) == set()  # Check alone changes no selection
    assert bpy.ops.affinity.select(index=0) == {"FINISHED"}
    assert bpy.context.mode == "EDIT_MESH"
    assert selected_faces(sphere) == expected


def test_next_walks_the_flagged_faces_worst_first():
    sphere = uv_sphere()
    clear_selection(sphere)
    q101 = sorted((r for r in findings(sphere) if r["code"] == "Q101"), key=lambda r: -r["value"])
    bpy.ops.affinity.check()
    row = bpy.context.scene.affinity.results[0]
    assert row.worst == pytest.approx(q101[0]["value"], rel=1e-6)
    seen = []
    for _ in range(3):
        assert bpy.ops.affinity.next() == {"FINISHED"}
        (face,) = selected_faces(sphere)
        seen.append(face)
    values = {r["face"]: r["value"] for r in q101}
    assert [values[f] for f in seen] == sorted((values[f] for f in seen), reverse=True)
    assert values[seen[0]] == q101[0]["value"] and len(set(seen)) == 3


def test_results_row_gives_the_worst_value_in_the_registrys_unit_under_every_reading():
    """Issue 39: the row's unit was blank under the barycentric reading, where the rule registry names one."""
    from affinity.rules import RULES, with_unit
    from affinity.settings import MEASURES

    uv_sphere()
    props = bpy.context.scene.affinity
    for measure in MEASURES:
        props.measure = measure
        assert bpy.ops.affinity.check() == {"FINISHED"}
        (row,) = props.results
        unit = RULES[row.code].unit_for(measure)
        assert unit and row.unit == unit, measure
        assert addon.worst_text(row) == with_unit(f"{row.worst:.4g}", unit)  # as affinity check writes it


def test_results_row_gives_the_visible_readings_unit_where_a_texture_was_read(tmp_path):
    """Through a Base Color image Q101's values are C in 1/255 steps (the CLI's JSON says so): the row
    showed them as texels."""
    sphere = uv_sphere()
    textured(sphere, tmp_path / "checker.png")
    rows = findings(sphere)
    assert {r["unit"] for r in rows} == {"1/255"}
    bpy.ops.affinity.check()
    (row,) = bpy.context.scene.affinity.results
    assert row.worst in {r["value"] for r in rows}
    assert row.unit == "1/255"
    assert addon.worst_text(row) == f"{row.worst:.4g}/255"


def test_check_lints_every_selected_mesh_object():
    with_uv = uv_sphere()
    without_uv = uv_sphere()
    without_uv.data.uv_layers.remove(without_uv.data.uv_layers[0])
    bpy.ops.object.camera_add()  # selected too, and not a mesh
    for obj in (with_uv, without_uv):
        obj.select_set(True)
    assert bpy.ops.affinity.check() == {"FINISHED"}
    props = bpy.context.scene.affinity
    assert [(r.object_name, r.code) for r in props.results] == [(with_uv.name, "Q101")]
    assert props.notes == f"{without_uv.name}: Q101 skipped: the mesh has no UV map"
    assert props.checked == 2


def test_mesh_without_uv_skips_q101_and_says_so():
    sphere = uv_sphere()
    sphere.data.uv_layers.remove(sphere.data.uv_layers[0])
    result = check_object(sphere)
    assert "Q101" not in {r["code"] for r in result.findings}
    assert any("Q101 skipped" in note and "no UV map" in note for note in result.notes)
    bpy.ops.affinity.check()
    assert "Q101 skipped" in bpy.context.scene.affinity.notes
    # Nothing to say when Q101 is not asked for.
    assert check_object(sphere, select=["Q2"]).notes == []


def test_modifiers_map_back_to_original_faces():
    sphere = uv_sphere()
    sphere.modifiers.new("Subdivision", "SUBSURF").levels = 1
    result = check_object(sphere, evaluated=True)
    original = result.conversion.original_face
    sizes = np.array([p.loop_total for p in sphere.data.polygons])
    # Catmull-Clark level 1 makes one quad per corner of every original face.
    np.testing.assert_array_equal(np.bincount(original, minlength=len(sizes)), sizes)
    assert all(r["original_face"] == original[r["face"]] for r in result.findings)
    assert sphere.data.attributes.get(ORIGINAL_FACE) is None  # the temporary tag is gone

    clear_selection(sphere)
    props = bpy.context.scene.affinity
    props.use_modifiers = True
    bpy.ops.affinity.check()
    assert props.results[0].code == "Q101"
    bpy.ops.affinity.select(index=0)
    q101 = [r for r in result.findings if r["code"] == "Q101"]
    assert selected_faces(sphere) == {r["original_face"] for r in q101}



def test_modifier_that_drops_attributes_turns_selection_off():
    sphere = uv_sphere()
    tree = bpy.data.node_groups.new("NewCube", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    cube = tree.nodes.new("GeometryNodeMeshCube")
    output = tree.nodes.new("NodeGroupOutput")
    tree.links.new(cube.outputs["Mesh"], output.inputs[0])
    sphere.modifiers.new("Replace", "NODES").node_group = tree
    result = check_object(sphere, evaluated=True, select=["Q2"], thresholds={"Q202": -1})
    assert result.conversion.mesh.n_faces == 6 and result.conversion.original_face is None
    assert any("selection is off" in note for note in result.notes)
    props = bpy.context.scene.affinity
    props.use_modifiers = True
    props.threshold_Q202 = -1  # every face flagged, so there is a row to try
    bpy.ops.affinity.check()
    assert "selection is off" in props.notes
    row = props.results[0]
    assert not row.selectable
    assert bpy.ops.affinity.select(index=0) == {"CANCELLED"}


@pytest.mark.parametrize("with_texture", [False, True])
def test_error_attribute_holds_the_worst_ratio_per_face(with_texture, tmp_path):
    """value / threshold of the face's worst finding, as the JSON gives both: through a texture the value is C
    and the threshold visible-warning, so a crease that shows nothing (C = 0) reads 0, not 1."""
    sphere = uv_sphere()
    if with_texture:
        textured(sphere, tmp_path / "checker.png")
    props = bpy.context.scene.affinity
    props.write_error = True
    bpy.ops.affinity.check()
    error = np.zeros(len(sphere.data.polygons), dtype=np.float32)
    sphere.data.attributes[ERROR_ATTRIBUTE].data.foreach_get("value", error)
    worst = defaultdict(float)
    rows = findings(sphere)
    assert {r["unit"] for r in rows} == ({"1/255"} if with_texture else {"texels"})
    for r in rows:
        worst[r["face"]] = max(worst[r["face"]], r["value"] / r["threshold"])
    expected = np.zeros_like(error)
    expected[list(worst)] = list(worst.values())
    np.testing.assert_allclose(error, expected, rtol=1e-5)
    assert sphere.data.color_attributes.active_color.name == ERROR_COLOR
    # Checking again does not read the error colours as vertex colours (no Q102).
    assert "Q102" not in {r["code"] for r in findings(sphere)}


def test_workbench_render_colours_the_flagged_faces(tmp_path):
    from affinity.blender.picture import render_error_picture

    path = tmp_path / "error.png"
    render_error_picture(str(path), width=96, height=72)
    image = bpy.data.images.load(str(path))
    pixels = np.array(image.pixels[:]).reshape(72, 96, 4)[::-1, :, :3]  # Blender stores rows bottom-up
    red_or_yellow = (pixels[..., 0] > 0.6) & (pixels[..., 2] < 0.2)
    grey = (np.ptp(pixels, axis=-1) < 0.05) & (pixels[..., 0] > 0.2)
    assert red_or_yellow.sum() > 50 and grey.sum() > 50
    # The sphere's top (north pole rings: flagged) is coloured, its middle (equator: passes) grey.
    column = pixels[:, 48]
    coloured_rows = np.flatnonzero((column[:, 0] > 0.6) & (column[:, 2] < 0.2))
    assert coloured_rows.size and coloured_rows.min() < 36


def bpy_alone(folder: Path) -> Path:
    """A site folder holding bpy and the distributions it requires, recursively, and nothing else: what a
    fresh venv with only ``pip install bpy`` has (symbolic links to this venv's copies)."""
    from importlib import metadata

    folder.mkdir()
    todo, seen = ["bpy"], set()
    while todo:
        name = todo.pop().lower().replace("_", "-")
        if name in seen:
            continue
        seen.add(name)
        dist = metadata.distribution(name)
        todo += [r.split(";")[0].split("[")[0].split("<")[0].split(">")[0].split("=")[0].split("!")[0].strip()
                 for r in dist.requires or [] if "extra ==" not in r]
        for top in {Path(str(f)).parts[0] for f in dist.files or []} - {"..", "bin"}:
            source = Path(dist.locate_file(top))
            if source.exists() and not (folder / top).exists():
                (folder / top).symlink_to(source)
    return folder


def _run_isolated(script: str, env_extra: dict, cwd: Path) -> subprocess.CompletedProcess:
    """Run ``script`` in this interpreter without site (no .pth files, so no editable install of
    the project) and without PYTHONPATH: only :func:`bpy_alone`'s folder is put on sys.path."""
    site_packages = bpy_alone(cwd / "bpy-alone")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(env_extra)
    return subprocess.run(
        [sys.executable, "-S", "-c", script, str(site_packages)],
        capture_output=True, text=True, env=env, cwd=cwd, timeout=600, check=False,
    )


#: A UV sphere whose material's Base Color is a packed 256 x 256 generated image (a script: run in a bare bpy).
PACKED_GRID_SPHERE = """
bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8)
image = bpy.data.images.new("grid", 256, 256)
image.generated_type = "COLOR_GRID"
image.pack()
material = bpy.data.materials.new("Grid")
if material.node_tree is None:
    material.use_nodes = True
node = material.node_tree.nodes.new("ShaderNodeTexImage")
node.image = image
material.node_tree.links.new(node.outputs["Color"], material.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
bpy.context.object.data.materials.append(material)
"""


def test_extension_zip_installs_into_bpy_and_runs_check_on_a_textured_mesh(tmp_path):
    """The zip alone, in a Python that has bpy and what bpy requires (no Pillow, pathspec, tqdm): Check reads
    a packed image's texels through Blender (C in 1/255 steps)."""
    from affinity.blender.build import build

    archive = build(tmp_path / "dist")
    script = f"""
import sys
sys.path.append(sys.argv[1])
import bpy
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.extensions.package_install_files(filepath={str(archive)!r}, repo="user_default", enable_on_install=True)
import affinity
print("affinity from", affinity.__file__)
{PACKED_GRID_SPHERE}
print("check", bpy.ops.affinity.check())
print("rows", [(r.code, r.count, r.unit) for r in bpy.context.scene.affinity.results])
print("pillow", "PIL" in sys.modules)
"""
    resources = tmp_path / "blender-user"
    result = _run_isolated(script, {"BLENDER_USER_RESOURCES": str(resources)}, tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    lines = dict(line.split(" ", 1) for line in result.stdout.splitlines() if line.split(" ", 1)[0] in
                 ("affinity", "check", "rows", "pillow"))
    assert lines["affinity"].startswith("from " + str(resources))  # the zip's wheel, not this checkout
    assert lines["check"] == "{'FINISHED'}"
    exec(PACKED_GRID_SPHERE, {"bpy": bpy})  # the same scene here, checked by this checkout
    expected = len([r for r in findings(bpy.context.object) if r["code"] == "Q101"])
    assert expected > 10
    assert lines["rows"] == f"[('Q101', {expected}, '1/255')]"
    assert lines["pillow"] == "False"


def test_affinity_check_does_not_import_bpy(tmp_path):
    script = """
import sys
sys.path[:0] = [sys.argv[1], sys.argv[2]]
from affinity.cli import main
try:
    main(["check", "--demo"])
except SystemExit:
    pass
import affinity.blender
print("bpy loaded:", "bpy" in sys.modules)
import importlib.util
print("bpy installed:", importlib.util.find_spec("bpy") is not None)
"""
    site_packages = sysconfig.get_paths()["purelib"]  # where bpy and NumPy are installed
    result = subprocess.run(
        [sys.executable, "-S", "-c", script, str(ROOT), site_packages],
        capture_output=True, text=True, cwd=tmp_path, timeout=300, check=False,
    )
    assert result.returncode == 0, result.stderr
    assert "bpy loaded: False" in result.stdout
    assert "bpy installed: True" in result.stdout


def trapezoid_strip():
    """Three quads in a row; the middle one a trapezoid carrying a rectangle of uv (Q101), its neighbours affine."""
    positions = [(0, 0, 0), (1, 0, 0), (2, 0, 0), (3, 0, 0), (0, 1, 0), (1.05, 1, 0), (1.95, 1, 0), (3, 1, 0)]
    faces = [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6)]
    uv = [(x / 3, y) for face in faces for x, y, _ in (positions[v] for v in face)]
    uv[4:8] = [(1 / 3, 0), (2 / 3, 0), (2 / 3, 1), (1 / 3, 1)]  # the middle quad's own rectangle: a uv seam
    return mesh_object("strip", positions, faces, uv)


def boundary_length(obj) -> float:
    """Total length of the edges used by one face: a T-junction would add the split edge twice over."""
    mesh = obj.data
    edge_of_loop = np.zeros(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("edge_index", edge_of_loop)
    users = np.bincount(edge_of_loop, minlength=len(mesh.edges))
    co = np.zeros(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    ends = np.zeros(2 * len(mesh.edges), dtype=np.int32)
    mesh.edges.foreach_get("vertices", ends)
    ends = ends.reshape(-1, 2)
    return float(np.linalg.norm(co[ends[:, 0]] - co[ends[:, 1]], axis=1)[users == 1].sum())


def test_fix_refines_the_selected_flagged_face_and_check_then_finds_it_clean():
    strip = trapezoid_strip()
    assert [(r["code"], r["face"]) for r in findings(strip)] == [("Q101", 1)]
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="DESELECT")
    bpy.ops.object.mode_set(mode="OBJECT")
    strip.data.polygons[1].select = True
    bpy.ops.object.mode_set(mode="EDIT")
    before = boundary_length(strip)
    assert bpy.ops.affinity.fix() == {"FINISHED"}
    assert bpy.context.mode == "EDIT_MESH"
    bpy.ops.object.mode_set(mode="OBJECT")
    assert len(strip.data.polygons) > 3 + 16
    assert boundary_length(strip) == pytest.approx(before)
    assert bpy.ops.affinity.check() == {"FINISHED"}
    assert [(r.code, r.count) for r in bpy.context.scene.affinity.results] == []
    assert findings(strip) == []
