"""Textures inside Blender: the add-on reads Blender's own images (never Pillow) and agrees with the command line.

Runs in the bpy venv, which has no Pillow (.ci/run installs it without; the first test says so). The command
line's side of each comparison runs in a Python that has Pillow (:mod:`helpers.blender_cli`). Both decode the
same PNG bytes: Pillow on the command line, Blender here.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers.blender_cli import run_cli_json
from helpers.blender_scenes import (
    base_color_material,
    empty_scene,  # noqa: F401 (autouse: every test in an empty scene)
    mesh_object,
    node_material,
)
from helpers.corpus import SHARED_MESHES

bpy = pytest.importorskip("bpy")

from affinity.blender import addon, findings  # noqa: E402
from affinity.blender.check import check_object  # noqa: E402
from affinity.blender.fix import fix_object  # noqa: E402

SPOT = SHARED_MESHES / "textured" / "spot_control_mesh_textured.obj"
SCORED = ("Q101", "Q102", "Q103")
LEVELS = ("info", "warning", "error")


def spot():
    if not SPOT.is_file():
        pytest.skip(f"{SPOT} not found (the shared meshes)")
    bpy.ops.wm.obj_import(filepath=str(SPOT))  # Blender's importer binds the MTL's map_Kd as an Image Texture
    return bpy.context.object


def by_face(rows, codes=("Q101",)) -> dict[tuple[str, int], dict]:
    return {(r["code"], r["face"]): r for r in rows if r["code"] in codes}


def test_this_venv_has_no_pillow():
    """The Blender leg runs where Blender's users are: no Pillow (bpy does not bring it)."""
    assert importlib.util.find_spec("PIL") is None


def test_spot_check_gives_the_command_lines_q101_faces_levels_and_values():
    obj = spot()
    rows = findings(obj)
    assert "PIL" not in sys.modules
    cli = run_cli_json("check", str(SPOT))["findings"]
    ours, theirs = by_face(rows), by_face(cli)
    assert ours.keys() == theirs.keys()
    assert len(ours) > 50
    assert {r["unit"] for r in ours.values()} == {"1/255"}  # C read through the texture on both sides
    assert {k: r["level"] for k, r in ours.items()} == {k: r["level"] for k, r in theirs.items()}
    keys = sorted(ours)
    c_here, c_there = (np.array([found[k]["value"] for k in keys]) for found in (ours, theirs))
    assert np.abs(c_here - c_there).max() < 1.0  # C to one step of 1/255 (float32 positions against the OBJ's text)
    assert (c_here >= 8).sum() > 10  # spots' edges: plainly visible creases
    np.testing.assert_allclose([ours[k]["shift"] for k in keys], [theirs[k]["shift"] for k in keys], rtol=1e-4)
    assert {ours[k]["texture"] for k in keys} == {"spot_texture.png"}
    # The panel's row gives the worst C as the JSON does, in 1/255 steps.
    assert bpy.ops.affinity.check() == {"FINISHED"}
    (row,) = [row for row in bpy.context.scene.affinity.results if row.code == "Q101"]
    assert (row.count, row.unit) == (len(theirs), "1/255")
    assert abs(row.worst - max(r["value"] for r in theirs.values())) < 1.0
    # The other rules agree too (faces are Blender's polygons, the OBJ's faces in order).
    others = {r["code"] for r in cli} - {"Q101"}
    assert by_face(rows, others).keys() == by_face(cli, others).keys()


def test_spot_fix_then_check_leaves_only_the_faces_fix_lists_as_the_command_line_does():
    obj = spot()
    mesh = obj.data
    tag = mesh.attributes.new("spot_face", "INT", "FACE")  # carried to untouched faces and a new face's pieces
    tag.data.foreach_set("value", np.arange(len(mesh.polygons), dtype=np.int32))
    plan = fix_object(obj, level="warning")
    assert len(plan.refine_faces) > 10
    cli = run_cli_json("fix", "--dry-run", str(SPOT))
    (entry,) = cli["files"] if "files" in cli else [cli]
    assert sorted(left["face"] for left in entry["left"]) == plan.left_faces.tolist()
    assert [left["reason"] for left in sorted(entry["left"], key=lambda x: x["face"])] == list(plan.left_reasons)
    assert sorted(r["face"] for r in entry["refine"]) == plan.refine_faces.tolist()

    after = findings(obj)
    source = np.zeros(len(obj.data.polygons), dtype=np.int32)
    obj.data.attributes["spot_face"].data.foreach_get("value", source)
    flagged = {int(source[r["face"]]) for r in after
               if r["code"] in SCORED and LEVELS.index(r["level"]) >= LEVELS.index("warning")}
    assert flagged <= set(plan.left_faces.tolist())


def _image_with_texels(name: str, texels: np.ndarray, colorspace: str = "sRGB"):
    """A Blender image holding ``texels`` (H, W, 4) uint8, row 0 the top (Blender stores rows bottom-up)."""
    height, width = texels.shape[:2]
    image = bpy.data.images.new(name, width, height, alpha=True)
    image.colorspace_settings.name = colorspace  # before the pixels: a change regenerates a generated image
    image.pixels.foreach_set((texels[::-1].astype(np.float32) / 255).ravel())
    return image


def _stripes(width: int, height: int, seed: int) -> np.ndarray:
    """(H, W, 4) uint8: sharp-edged blobs, so a uv shift crosses edges (C well above a step)."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:height, 0:width]
    texels = np.full((height, width, 4), 255, dtype=np.uint8)
    for _ in range(12):
        cx, cy, r = rng.uniform(0, width), rng.uniform(0, height), rng.uniform(2, max(width, height) / 4)
        texels[(x - cx) ** 2 + (y - cy) ** 2 < r * r, :3] = rng.integers(0, 256, 3)
    return texels


def _trapezoids(uv_offsets):
    """One trapezoid quad per uv offset, each carrying the unit uv square moved by its offset: Q101 flags each."""
    positions, faces, uv = [], [], []
    for k, (du, dv) in enumerate(uv_offsets):
        x = 3.0 * k
        positions += [(x, 0, 0), (x + 2, 0, 0), (x + 1.5, 1, 0), (x + 0.5, 1, 0)]
        faces.append(tuple(range(4 * k, 4 * k + 4)))
        uv += [(du, dv), (du + 1, dv), (du + 1, dv + 1), (du, dv + 1)]
    return mesh_object("trapezoids", positions, faces, uv)


def _obj_file(obj, folder: Path, map_kd: str) -> Path:
    """``obj`` written as an OBJ (Blender's exporter) whose MTL names ``map_Kd``."""
    path = folder / "mesh.obj"
    bpy.ops.wm.obj_export(filepath=str(path), export_materials=False, export_selected_objects=True,
                          export_normals=False)
    (folder / "mesh.mtl").write_text(f"newmtl Textured\nmap_Kd {map_kd}\n")
    path.write_text("mtllib mesh.mtl\nusemtl Textured\n" + path.read_text())
    return path


def test_packed_image_is_read_through_blender_as_the_command_line_reads_its_png(tmp_path):
    obj = _trapezoids([(0, 0)])
    texels = _stripes(48, 32, seed=1)
    image = _image_with_texels("packed", texels)
    image.filepath_raw = str(tmp_path / "packed.png")
    image.file_format = "PNG"
    image.save()
    image.pack()
    (tmp_path / "packed.png").rename(tmp_path / "on_disk.png")  # Blender has only the packed bytes now
    assert image.packed_file is not None
    base_color_material(obj, image)
    ours = by_face(findings(obj, select=["Q101"], thresholds={"Q101": 0}))
    theirs = by_face(run_cli_json("check", "--select", "Q101", "--threshold", "Q101=0",
                             str(_obj_file(obj, tmp_path, "on_disk.png")))["findings"])
    assert ours.keys() == theirs.keys() == {("Q101", 0)}
    here, there = ours["Q101", 0], theirs["Q101", 0]
    assert here["unit"] == there["unit"] == "1/255" and here["texture"] == "packed"
    assert abs(here["value"] - there["value"]) < 1.0 and there["value"] > 8
    assert here["shift"] == pytest.approx(there["shift"], rel=1e-5)  # counted in the image's 48 x 32 texels


def test_packed_udim_tiles_are_each_read_at_their_own_size(tmp_path):
    obj = _trapezoids([(0, 0), (1, 0)])  # tile 1001, then 1002
    image = bpy.data.images.new("tiles", 64, 64, tiled=True)
    with bpy.context.temp_override(edit_image=image):
        assert bpy.ops.image.tile_add(number=1002, count=1, fill=True, width=32, height=16) == {"FINISHED"}
    assert [tuple(t.size) for t in image.tiles] == [(64, 64), (32, 16)]
    image.filepath_raw = str(tmp_path / "tiles.<UDIM>.png")
    image.file_format = "PNG"
    for tile, (width, height), seed in ((1001, (64, 64), 2), (1002, (32, 16), 3)):
        single = _image_with_texels(f"tile{tile}", _stripes(width, height, seed))
        single.filepath_raw = str(tmp_path / f"tiles.{tile}.png")
        single.file_format = "PNG"
        single.save()
    image.reload()  # the tiles now hold the files' texels
    image.pack()
    cli_folder = tmp_path / "cli"
    cli_folder.mkdir()
    for tile in (1001, 1002):  # Blender keeps only the packed tiles; the command line reads the files
        (tmp_path / f"tiles.{tile}.png").rename(cli_folder / f"tiles.{tile}.png")
    assert [p.tile_number for p in image.packed_files] == [1001, 1002]
    base_color_material(obj, image)
    ours = by_face(findings(obj, select=["Q101"], thresholds={"Q101": 0}))
    theirs = by_face(run_cli_json("check", "--select", "Q101", "--threshold", "Q101=0",
                                  str(_obj_file(obj, cli_folder, "tiles.<UDIM>.png")))["findings"])
    assert ours.keys() == theirs.keys() == {("Q101", 0), ("Q101", 1)}
    for key in ours:
        assert ours[key]["unit"] == theirs[key]["unit"] == "1/255"
        assert abs(ours[key]["value"] - theirs[key]["value"]) < 1.0
        assert ours[key]["shift"] == pytest.approx(theirs[key]["shift"], rel=1e-5)
    assert addon.texture_line(obj, bpy.context.scene.affinity) == "Texture: tiles, 2 UDIM tiles (read by Blender)"
    # The same uv crease counted in each tile's own texels: tile 1002 is half as wide and a quarter as high.
    assert ours["Q101", 1]["shift"] < 0.6 * ours["Q101", 0]["shift"]
    assert max(ours[key]["value"] for key in ours) > 8


def test_subdivision_surface_modifier_is_read_and_its_profile_offered():
    """The Catmull-Clark modifier's levels and smoothing, as the profile and OpenSubdiv rules they draw; the
    panel's notes say the findings are of the cage."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8)
    sphere = bpy.context.object
    assert check_object(sphere).subdivision is None
    modifier = sphere.modifiers.new("Smooth", "SUBSURF")
    modifier.levels, modifier.render_levels = 1, 2
    modifier.uv_smooth, modifier.boundary_smooth = "PRESERVE_CORNERS", "ALL"
    found = check_object(sphere).subdivision
    assert (found.name, found.scheme, found.levels, found.render_levels) == ("Smooth", "catmullClark", 1, 2)
    assert (found.fvar_interpolation, found.boundary_interpolation) == ("cornersOnly", "edgeOnly")
    assert (found.profile, found.render_profile) == ("--profile blender-viewport", "--profile blender-render")
    bpy.ops.affinity.check()
    assert bpy.context.scene.affinity.notes == (
        "Sphere: Subdivision Surface 'Smooth' (catmullClark, viewport level 1, render level 2, fvar cornersOnly, "
        "boundary edgeOnly): findings are of the cage: Blender draws --profile blender-viewport in the viewport, "
        "--profile blender-render in renders")
    modifier.subdivision_type, modifier.levels, modifier.show_render = "SIMPLE", 3, False
    found = check_object(sphere).subdivision
    assert (found.scheme, found.profile, found.render_profile) == ("bilinear", "--subdivision level:3",
                                                                    "--profile game")


def _normal_texels(width: int, height: int, seed: int) -> np.ndarray:
    """(H, W, 4) uint8 tangent-space normals, blue dominant: flat with tilted discs."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:height, 0:width]
    normals = np.zeros((height, width, 3))
    normals[..., 2] = 1.0
    for _ in range(10):
        cx, cy, r = rng.uniform(0, width), rng.uniform(0, height), rng.uniform(2, width / 4)
        tilt = rng.uniform(-0.6, 0.6, 2)
        normals[(x - cx) ** 2 + (y - cy) ** 2 < r * r, :2] = tilt
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    texels = np.full((height, width, 4), 255, dtype=np.uint8)
    texels[..., :3] = np.rint((normals + 1) * 127.5)
    return texels


def test_normal_map_and_mapping_node_read_as_the_mtl_norm_and_scale_are(tmp_path):
    """A Normal Map node's image is a normal map (C in degrees, as MTL ``norm``); a Mapping node's scale and
    location are the map's ``-s`` and ``-o``."""
    obj = _trapezoids([(0, 0)])
    texels = _normal_texels(40, 40, seed=4)
    image = _image_with_texels("bumps", texels, "Non-Color")
    image.filepath_raw, image.file_format = str(tmp_path / "bumps.png"), "PNG"
    image.save()
    material = node_material("Textured")
    tree = material.node_tree
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (2.0, 1.5, 1.0)
    mapping.inputs["Location"].default_value = (0.25, 0.1, 0.0)
    uv = tree.nodes.new("ShaderNodeUVMap")
    uv.uv_map = "UVMap"
    tree.links.new(uv.outputs["UV"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], node.inputs["Vector"])
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    tree.links.new(node.outputs["Color"], normal_map.inputs["Color"])
    tree.links.new(normal_map.outputs["Normal"], tree.nodes["Principled BSDF"].inputs["Normal"])
    obj.data.materials.append(material)
    ours = by_face(findings(obj, select=["Q101"], thresholds={"Q101": 0}))
    path = _obj_file(obj, tmp_path, "")
    (tmp_path / "mesh.mtl").write_text("newmtl Textured\nnorm -s 2 1.5 1 -o 0.25 0.1 0 bumps.png\n")
    theirs = by_face(run_cli_json("check", "--select", "Q101", "--threshold", "Q101=0", str(path))["findings"])
    assert ours.keys() == theirs.keys() == {("Q101", 0)}
    here, there = ours["Q101", 0], theirs["Q101", 0]
    assert here["unit"] == there["unit"] == "degrees" and here["role"] == there["role"] == "normal"
    assert abs(here["value"] - there["value"]) < 0.5 and there["value"] > 2
    assert here["shift"] == pytest.approx(there["shift"], rel=1e-5)


def _bilinear(texels: np.ndarray, uv: np.ndarray, extension: str) -> np.ndarray:
    """(N, C) float64: ``texels`` (H, W, C) filtered bilinearly at ``uv`` (N, 2), row 0 the top, as Blender's
    Image Texture node reads outside the image: REPEAT wraps, EXTEND clamps to the edge texels, CLIP reads zero
    outside, MIRROR reflects (the edge texel repeated)."""
    height, width = texels.shape[:2]
    x, y = uv[:, 0] * width - 0.5, (1.0 - uv[:, 1]) * height - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]

    def texel(i, j):
        inside = (i >= 0) & (i < width) & (j >= 0) & (j < height)
        if extension == "REPEAT":
            i, j = i % width, j % height
        elif extension == "MIRROR":
            i, j = i % (2 * width), j % (2 * height)
            i, j = np.where(i < width, i, 2 * width - 1 - i), np.where(j < height, j, 2 * height - 1 - j)
        else:
            i, j = np.clip(i, 0, width - 1), np.clip(j, 0, height - 1)
        value = texels[j, i].astype(np.float64)
        return value * inside[:, None] if extension == "CLIP" else value

    top = texel(x0, y0) * (1 - fx) + texel(x0 + 1, y0) * fx
    bottom = texel(x0, y0 + 1) * (1 - fx) + texel(x0 + 1, y0 + 1) * fx
    return top * (1 - fy) + bottom * fy


def _crease_by_dense_sampling(xy: np.ndarray, uv: np.ndarray, texels: np.ndarray, extension: str) -> float:
    """C of one planar quad, corners ``xy`` (4, 2) carrying ``uv`` (4, 2), by brute force: 301 x 301 points of its
    bilinear patch, the split's uv against the bilinear uv, both diagonals, in 1/255 steps (a lower bound)."""
    s, t = (a.ravel() for a in np.meshgrid(*2 * [np.linspace(0, 1, 301)]))
    weights = np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t], axis=1)
    points, exact = weights @ xy, weights @ uv
    seen = _bilinear(texels, exact, extension)
    worst = 0.0
    for first, second in (((0, 1, 2), (0, 2, 3)), ((1, 2, 3), (1, 3, 0))):
        split = np.full_like(exact, np.nan)
        for triangle in (first, second):
            a, b, c = xy[list(triangle)]
            matrix = np.array([b - a, c - a]).T
            wb, wc = np.linalg.solve(matrix, (points - a).T)
            inside = (wb >= -1e-12) & (wc >= -1e-12) & (wb + wc <= 1 + 1e-12)
            uv_a, uv_b, uv_c = uv[list(triangle)]
            split[inside] = ((1 - wb - wc)[:, None] * uv_a + wb[:, None] * uv_b + wc[:, None] * uv_c)[inside]
        worst = max(worst, float(np.abs(_bilinear(texels, split, extension) - seen)[:, :3].max()))
    return worst


@pytest.mark.parametrize("extension", ["REPEAT", "EXTEND", "CLIP", "MIRROR"])
def test_each_extension_reads_as_blender_samples_outside_the_image(extension):
    """A quad whose uv reach 0.3 to 0.45 images outside [0, 1]: C equals dense sampling through the extension's
    own rule (and differs from Repeat's where the outside differs)."""
    obj = _trapezoids([(-0.3, -0.45)])
    texels = _stripes(32, 24, seed=8)
    base_color_material(obj, _image_with_texels("blobs", texels))
    node = next(n for n in obj.data.materials[0].node_tree.nodes if n.type == "TEX_IMAGE")
    node.extension = extension
    # visible-error above any C: the reading refines to the maximum instead of stopping at "at least 8"
    result = check_object(obj, select=["Q101"], thresholds={"Q101": 0}, visible_error=1000.0)
    assert result.notes == []
    (row,) = result.findings
    assert "bound" not in row
    xy = np.array([(0, 0), (2, 0), (1.5, 1), (0.5, 1)], dtype=np.float64)
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=np.float64) + (-0.3, -0.45)
    truth = _crease_by_dense_sampling(xy, uv, texels, extension)
    assert truth - 0.01 <= row["value"] <= truth + 1.0
    if extension != "REPEAT":
        assert abs(_crease_by_dense_sampling(xy, uv, texels, "REPEAT") - truth) > 2  # the extension matters here


def test_an_interpolation_other_than_linear_is_said():
    obj = _trapezoids([(0, 0)])
    base_color_material(obj, _image_with_texels("blobs", _stripes(32, 32, seed=6)))
    node = next(n for n in obj.data.materials[0].node_tree.nodes if n.type == "TEX_IMAGE")
    node.extension, node.interpolation = "EXTEND", "Closest"
    result = check_object(obj, select=["Q101"], thresholds={"Q101": 0})
    assert result.notes == ["Textured: image 'blobs' (base colour) has interpolation Closest: read as Linear"]
    assert {r["unit"] for r in result.findings} == {"1/255"}


def test_an_image_on_another_uv_map_is_left_out_and_said(tmp_path):
    obj = _trapezoids([(0, 0)])
    obj.data.uv_layers.new(name="Second")
    base_color_material(obj, _image_with_texels("blobs", _stripes(32, 32, seed=5)))
    node = next(n for n in obj.data.materials[0].node_tree.nodes if n.type == "TEX_IMAGE")
    uv = obj.data.materials[0].node_tree.nodes.new("ShaderNodeUVMap")
    uv.uv_map = "Second"
    obj.data.materials[0].node_tree.links.new(uv.outputs["UV"], node.inputs["Vector"])
    result = check_object(obj, select=["Q101"], thresholds={"Q101": 0})
    assert result.notes == ["Textured: image 'blobs' (base colour) reads UV map 'Second', not the linted "
                            "'UVMap': not read"]
    assert {r["unit"] for r in result.findings} == {"texels"}
    assert {r["unit"] for r in findings(obj, select=["Q101"], thresholds={"Q101": 0}, uv_layer="Second")} \
        == {"1/255"}


def test_results_picture_shows_the_textured_spot_and_the_panels_rows(tmp_path):
    from affinity.blender.picture import render_results_picture

    if not SPOT.is_file():
        pytest.skip(f"{SPOT} not found (the shared meshes)")
    path = tmp_path / "spot.png"
    lines = render_results_picture(str(path), str(SPOT), width=240, height=140)
    rows = bpy.context.scene.affinity.results
    assert lines[0].startswith(f"Q101 uv-disaffine   {rows[0].count}   worst ") and lines[0].count("/255") == 1
    image = bpy.data.images.load(str(path))
    pixels = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(pixels)
    rgb = pixels.reshape(140, 240, 4)[::-1, :, :3]
    left, right = rgb[:, :120], rgb[:, 120:]
    dark_grey = (rgb.max(axis=-1) < 0.25) & (np.ptp(rgb, axis=-1) < 0.05)  # Spot's black patches, or text
    red = (right[..., 0] > 0.6) & (right[..., 1] < 0.3) & (right[..., 2] < 0.2)
    assert dark_grey[:90, :120].sum() > 30 and red.sum() > 100
    assert not ((left[..., 0] > 0.6) & (left[..., 1] < 0.3) & (left[..., 2] < 0.2)).any()  # no error colours left


def _png16(path: Path, rgb: np.ndarray) -> None:
    """Write (H, W, 3) uint16 ``rgb`` as a 16-bit RGB PNG (zlib and struct: this venv has no image writer)."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    height, width = rgb.shape[:2]
    rows = b"".join(b"\0" + row.astype(">u2").tobytes() for row in rgb)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 16, 2, 0, 0, 0))
                     + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def test_a_16_bit_png_reads_within_a_step_of_the_command_lines_8_bits(tmp_path):
    """Blender holds a 16-bit PNG as scene-linear floats; encoded back with the sRGB curve and rounded, its
    texels are within a step of the top 8 bits the command line reads, and so is C."""
    obj = _trapezoids([(0, 0)])
    rgb = _stripes(40, 24, seed=7)[..., :3].astype(np.uint16) * 257  # 16-bit values whose top byte is the 8-bit one
    rgb[::3] += 100  # and low bytes that are not
    _png16(tmp_path / "deep.png", rgb)
    image = bpy.data.images.load(str(tmp_path / "deep.png"))
    assert image.is_float and image.colorspace_settings.name == "sRGB"
    base_color_material(obj, image)
    ours = by_face(findings(obj, select=["Q101"], thresholds={"Q101": 0}))
    theirs = by_face(run_cli_json("check", "--select", "Q101", "--threshold", "Q101=0",
                                  str(_obj_file(obj, tmp_path, "deep.png")))["findings"])
    assert ours.keys() == theirs.keys() == {("Q101", 0)}
    assert ours["Q101", 0]["unit"] == theirs["Q101", 0]["unit"] == "1/255"
    assert abs(ours["Q101", 0]["value"] - theirs["Q101", 0]["value"]) <= 1.0 and theirs["Q101", 0]["value"] > 8
