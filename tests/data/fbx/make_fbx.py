"""Make the FBX test data from the shared OBJ meshes with Blender (bpy), as an artist's export would.

Run with a Python that has bpy (Blender as a module; Python 3.11, NumPy < 2, a venv of its own):

    python tests/data/fbx/make_fbx.py [--meshes ../shared/meshes] [--out tests/data/fbx]

Each ``NAME.obj`` of the shared meshes is imported (``wm.obj_import``, Blender's defaults: Y up, -Z forward)
and exported as ``NAME.fbx`` (``export_scene.fbx``): polygons as they are (no triangulation), no
modifiers, no smoothing groups, no animation or leaf bones, units written as the FBX scale (1 m a unit), so
the world positions are the OBJ's (up to float32 rounding and the axis round trip). The textured Spot is
exported twice: ``spot_textured_external.fbx`` with its image copied beside it
(``spot_textured_external.fbm/``) and ``spot_textured_embedded.fbx`` with the image inside the file
(``embed_textures``). Blender writes its computed normals into every FBX, whether the OBJ had normals or not.

Two scenes are built on Spot: ``spot_instanced.fbx``, the Spot mesh under an empty ``Root`` twice, as
``Root/Body`` and a linked duplicate ``Root/Copy`` (one geometry, two nodes; the copy moved, turned and
scaled uniformly), and ``spot_two_uv_sets.fbx``, Spot with a second uv set ``Planar`` after its own
``UVMap``: the mesh's own x and y (Blender's importer turns the object, not its vertices).
"""

from __future__ import annotations

import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
#: The shared meshes exported, by file name (all of them at the time of writing, 6.5 MB of OBJ; 3 MB of FBX).
MESHES = ("spot_control_mesh.obj", "makehuman_base_hm08.obj", "gen_spot_cc4.obj", "gen_uv_sphere_64x32.obj",
          "gen_vase_revolution.obj", "osd_catmark_bishop.obj", "osd_catmark_car.obj", "osd_catmark_nonquads.obj",
          "osd_catmark_torus.obj", "tinyobjloader_cube_vertexcol.obj")
TEXTURED = "textured/spot_control_mesh_textured.obj"


def export(bpy, obj_path: str, fbx_path: str, embed: bool = False) -> None:
    """Import one OBJ into an empty scene and export it as FBX (see the module docstring)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.obj_import(filepath=obj_path)
    bpy.ops.export_scene.fbx(filepath=fbx_path, object_types={"MESH"}, use_mesh_modifiers=False,
                             mesh_smooth_type="OFF", use_triangles=False, add_leaf_bones=False, bake_anim=False,
                             apply_scale_options="FBX_SCALE_UNITS", path_mode="COPY", embed_textures=embed)


def instanced(bpy, obj_path: str, fbx_path: str) -> None:
    """Spot twice, one geometry: ``/Root/Body`` and its linked duplicate ``/Root/Copy``."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.obj_import(filepath=obj_path)
    body = bpy.context.selected_objects[0]
    body.name = "Body"
    root = bpy.data.objects.new("Root", None)
    bpy.context.scene.collection.objects.link(root)
    copy = bpy.data.objects.new("Copy", body.data)
    bpy.context.scene.collection.objects.link(copy)
    copy.location, copy.rotation_euler, copy.scale = (3.0, 0.0, 0.5), (0.0, 0.0, 0.7), (2.0, 2.0, 2.0)
    body.parent = copy.parent = root
    bpy.ops.export_scene.fbx(filepath=fbx_path, object_types={"MESH", "EMPTY"}, use_mesh_modifiers=False,
                             mesh_smooth_type="OFF", add_leaf_bones=False, bake_anim=False,
                             apply_scale_options="FBX_SCALE_UNITS")


def two_uv_sets(bpy, obj_path: str, fbx_path: str) -> None:
    """Spot with a second uv set ``Planar``: each corner's vertex x, y in the mesh's own coordinates."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.obj_import(filepath=obj_path)
    mesh = bpy.context.selected_objects[0].data
    planar = mesh.uv_layers.new(name="Planar")
    for loop in mesh.loops:
        x, y, _ = mesh.vertices[loop.vertex_index].co
        planar.data[loop.index].uv = (x, y)
    bpy.ops.export_scene.fbx(filepath=fbx_path, object_types={"MESH"}, use_mesh_modifiers=False,
                             mesh_smooth_type="OFF", add_leaf_bones=False, bake_anim=False,
                             apply_scale_options="FBX_SCALE_UNITS")


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default=os.path.join(HERE, "..", "..", "..", "..", "shared", "meshes"))
    parser.add_argument("--out", default=HERE)
    args = parser.parse_args(argv)
    import bpy

    for name in MESHES:
        export(bpy, os.path.join(args.meshes, name), os.path.join(args.out, name[:-4] + ".fbx"))
    textured = os.path.join(args.meshes, TEXTURED)
    export(bpy, textured, os.path.join(args.out, "spot_textured_external.fbx"))
    export(bpy, textured, os.path.join(args.out, "spot_textured_embedded.fbx"), embed=True)
    spot = os.path.join(args.meshes, "spot_control_mesh.obj")
    instanced(bpy, spot, os.path.join(args.out, "spot_instanced.fbx"))
    two_uv_sets(bpy, spot, os.path.join(args.out, "spot_two_uv_sets.fbx"))


if __name__ == "__main__":
    main(sys.argv[1 + sys.argv.index("--") if "--" in sys.argv else 1:])
