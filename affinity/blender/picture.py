"""Headless Workbench pictures of the extension at work: ``python -m affinity.blender.picture -o out.png``.

Runs inside ``bpy`` (the wheel) in background mode, where OpenGL viewport
captures and screenshots of the interface do not work but
``bpy.ops.render.render`` with the Workbench engine does.

- :func:`render_error_picture`: a lat-long UV sphere (``primitive_uv_sphere_add``)
  checked by the extension's **Check** with *Write affinity_error* on, drawn with
  the Workbench "Attribute" colouring of ``affinity_error_color``: grey faces pass,
  yellow ones are at the Q101 limit, red ones four times over it and beyond.
- :func:`render_results_picture` (``--mesh PATH``): a textured OBJ imported by
  Blender's own importer (its MTL's image bound as an Image Texture), checked the
  same way, drawn through its texture beside its ``affinity_error`` colouring, with
  the results list's rows (as the panel lists them: rule, count, worst value)
  written under it as text in the scene.
"""

from __future__ import annotations

import argparse
import sys


def _scene(width: int, height: int, background: float):
    """The current scene set up for a Workbench render of ``width`` x ``height`` px on a grey background."""
    import bpy

    scene = bpy.context.scene
    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.show_object_outline = True
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.world = scene.world or bpy.data.worlds.new("World")
    scene.world.color = (background,) * 3
    scene.view_settings.view_transform = "Standard"  # the colours as they are, white as white
    return scene


def _camera(scene, location, target=(0.0, 0.0, 0.0), ortho_scale: float | None = None):
    import bpy
    from mathutils import Vector

    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    camera.location = Vector(location)
    camera.rotation_euler = (Vector(target) - camera.location).to_track_quat("-Z", "Y").to_euler()
    if ortho_scale is not None:
        camera.data.type, camera.data.ortho_scale = "ORTHO", ortho_scale
    return camera


def _render(scene, path: str) -> None:
    import bpy

    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)


def _checked(texture_size: int | None = None) -> None:
    """Run the extension's Check on the selected objects with *Write affinity_error* on."""
    import bpy

    from . import addon

    if not hasattr(bpy.types.Scene, "affinity"):
        addon.register()
    props = bpy.context.scene.affinity
    props.write_error = True
    if texture_size is not None:
        props.texture_size = texture_size
    bpy.ops.affinity.check()


def render_error_picture(path: str, width: int = 360, height: int = 270, texture_size: int = 256,
                         segments: int = 32, rings: int = 16) -> None:
    """Build the UV sphere scene in the current ``bpy`` session and render it to the PNG ``path``."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=rings)
    _checked(texture_size)
    scene = _scene(width, height, 1.0)
    scene.display.shading.color_type = "VERTEX"  # "Attribute" in the UI: the active colour attribute
    _camera(scene, (3.0, -3.0, 2.0))
    _render(scene, path)


def results_lines() -> list[str]:
    """The results list of the last Check, a line a row as the panel shows it: rule, count, worst, object."""
    import bpy

    from .addon import worst_text

    return [f"{row.code} {row.rule_name}   {row.count}   worst {worst_text(row)}   {row.object_name}"
            for row in bpy.context.scene.affinity.results]


def render_results_picture(path: str, mesh: str, width: int = 720, height: int = 420) -> list[str]:
    """Import the OBJ ``mesh`` with Blender's importer, Check it and picture it twice side by side (through its
    texture, and in its ``affinity_error`` colours) over the results list's rows; returns those rows.

    Workbench draws every object with one colour source, so the scene is rendered once through the textures
    and once in the attribute colours, and the picture takes its left half from the first, its right half
    from the second (the rows' text is black in both)."""
    import bpy
    import numpy as np

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.obj_import(filepath=str(mesh))
    textured = bpy.context.object
    _checked()
    lines = results_lines()
    coloured = textured.copy()  # the same mesh data: the same error colours
    scene = _scene(width, height, 1.0)
    scene.collection.objects.link(coloured)
    low, high = (np.array([f(v[i] for v in textured.bound_box) for i in range(3)]) for f in (min, max))
    extent, centre = float((high - low).max()), (low + high) / 2
    textured.location.x -= 0.6 * extent + centre[0]
    coloured.location.x += 0.6 * extent - centre[0]
    for obj in (textured, coloured):
        obj.rotation_euler.z -= 0.7  # a three-quarter view: the flank and its spots
    top = low[2] - 0.15 * extent
    for index, line in enumerate(lines[:6]):
        _text(scene, line, (-1.25 * extent, -extent, top - 0.13 * extent * index), 0.085 * extent)
    bottom = top - 0.13 * extent * min(len(lines), 6)
    middle = (high[2] + bottom) / 2
    _camera(scene, (0.0, -6.0 * extent, middle), (0.0, 0.0, middle),
            ortho_scale=max(2.7 * extent, (high[2] - bottom + 0.2 * extent) * width / height))
    halves = []
    for color_type in ("TEXTURE", "VERTEX"):
        scene.display.shading.color_type = color_type
        _render(scene, path)
        image = bpy.data.images.load(str(path), check_existing=False)
        pixels = np.empty(len(image.pixels), dtype=np.float32)
        image.pixels.foreach_get(pixels)
        halves.append(pixels.reshape(height, width, 4))
        bpy.data.images.remove(image)
    picture = np.concatenate([halves[0][:, : width // 2], halves[1][:, width // 2 :]], axis=1)
    out = bpy.data.images.new("results", width, height)
    out.pixels.foreach_set(picture.ravel())
    out.filepath_raw, out.file_format = str(path), "PNG"
    out.save()
    return lines


def _text(scene, body: str, location, size: float) -> None:
    """A line of black text facing the camera (which looks along +y)."""
    import bpy

    curve = bpy.data.curves.new("line", "FONT")
    curve.body, curve.size = body, size
    text = bpy.data.objects.new("line", curve)
    text.location = location
    text.rotation_euler = (1.5707963, 0.0, 0.0)
    material = bpy.data.materials.new("ink")
    material.diffuse_color = (0.0, 0.0, 0.0, 1.0)
    curve.materials.append(material)
    scene.collection.objects.link(text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m affinity.blender.picture", description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", default=None, help="the PNG (default: reports/blender/NAME.png)")
    parser.add_argument("--mesh", help="a textured OBJ: picture its Check results instead of the UV sphere's")
    parser.add_argument("--width", type=int, default=None)
    parser.add_argument("--height", type=int, default=None)
    args = parser.parse_args(argv)
    size = {k: v for k, v in (("width", args.width), ("height", args.height)) if v is not None}
    if args.mesh:
        for line in render_results_picture(args.out or "reports/blender/spot_results.png", args.mesh, **size):
            print(line)
    else:
        render_error_picture(args.out or "reports/blender/uv_sphere_error.png", **size)
    return 0


if __name__ == "__main__":
    sys.exit(main())
