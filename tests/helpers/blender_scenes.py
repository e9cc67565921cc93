"""Small Blender scenes the Blender tests build (``bpy`` imported when called: these run in the bpy venv only)."""

from __future__ import annotations

import pytest


@pytest.fixture(autouse=True)
def empty_scene():
    """Every test starts from an empty factory scene with the extension registered (bpy is one Blender
    session per process). A test module takes it by importing it."""
    import bpy

    from affinity.blender import addon

    bpy.ops.wm.read_factory_settings(use_empty=True)
    if not hasattr(bpy.types.Scene, "affinity"):
        addon.register()
    yield


def node_material(name: str):
    """A new material with its node tree (before Blender 5.0 a new material has none until ``use_nodes``)."""
    import bpy

    material = bpy.data.materials.new(name)
    if material.node_tree is None:
        material.use_nodes = True
    return material


def base_color_material(obj, image, name: str = "Textured"):
    """Give ``obj`` a new material whose Principled BSDF's Base Color is an Image Texture of ``image``."""
    material = node_material(name)
    tree = material.node_tree
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    tree.links.new(node.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    obj.data.materials.append(material)
    return material


def mesh_object(name: str, positions, faces, uv):
    """A new mesh object from ``positions`` and ``faces`` with one uv map ``UVMap`` holding ``uv`` (one pair per
    corner, in face order), linked to the scene, selected and active."""
    import bpy
    import numpy as np

    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(positions, [], faces)
    mesh.update()
    layer = mesh.uv_layers.new(name="UVMap")
    layer.data.foreach_set("uv", np.array(uv, dtype=np.float32).ravel())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj
