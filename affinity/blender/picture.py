"""A headless Workbench render of ``affinity_error``: ``python -m affinity.blender.picture -o out.png``.

Runs inside ``bpy`` (the wheel) in background mode, where OpenGL viewport
captures do not work but ``bpy.ops.render.render`` with the Workbench engine
does. The scene: a lat-long UV sphere (``primitive_uv_sphere_add``) checked by
the extension's **Check** with *Write affinity_error* on, drawn with the
Workbench "Attribute" colouring of ``affinity_error_color``: grey faces pass,
yellow ones are at the Q101 limit, red ones four times over it and beyond.
"""

from __future__ import annotations

import argparse
import sys


def render_error_picture(path: str, width: int = 360, height: int = 270, texture_size: int = 256,
                         segments: int = 32, rings: int = 16) -> None:
    """Build the scene in the current ``bpy`` session and render it to the PNG ``path``."""
    import bpy
    from mathutils import Vector

    from . import addon

    bpy.ops.wm.read_factory_settings(use_empty=True)
    if not hasattr(bpy.types.Scene, "affinity"):
        addon.register()
    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=rings)
    scene = bpy.context.scene
    props = scene.affinity
    props.write_error = True
    props.texture_size = texture_size
    bpy.ops.affinity.check()

    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.color_type = "VERTEX"  # "Attribute" in the UI: the active colour attribute
    shading.show_object_outline = True
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.world = scene.world or bpy.data.worlds.new("World")
    scene.world.color = (1.0, 1.0, 1.0)

    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    camera.location = Vector((3.0, -3.0, 2.0))
    camera.rotation_euler = (-camera.location).to_track_quat("-Z", "Y").to_euler()
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m affinity.blender.picture", description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", default="reports/blender/uv_sphere_error.png")
    parser.add_argument("--width", type=int, default=360)
    parser.add_argument("--height", type=int, default=270)
    args = parser.parse_args(argv)
    render_error_picture(args.out, args.width, args.height)
    return 0


if __name__ == "__main__":
    sys.exit(main())
