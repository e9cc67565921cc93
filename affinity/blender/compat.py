"""Every place where the Blender Python API differs between the versions we support.

The extension declares Blender 4.2 as its minimum (the first version that
installs extensions from a ``blender_manifest.toml``). Everything else in
:mod:`affinity.blender` uses API that is documented and unchanged from 4.2 to
5.0; what moved, or is announced to move, is read through the functions here,
so a new Blender release means editing this one module.

Nothing here imports ``bpy`` at module level; functions that need the module
import it when called.
"""

from __future__ import annotations

import numpy as np


def version() -> tuple[int, int, int]:
    """The running Blender's version, e.g. ``(5, 0, 1)``."""
    import bpy

    return tuple(bpy.app.version)


def read_floats(collection, name: str, width: int) -> np.ndarray:
    """``collection.foreach_get(name)`` into a (len(collection), width) float64 array.

    Blender fills a float32 buffer without a Python object per element; the
    copy to float64 is the precision the measures work in.
    """
    out = np.empty(len(collection) * width, dtype=np.float32)
    collection.foreach_get(name, out)
    return out.reshape(-1, width).astype(np.float64)


def read_ints(collection, name: str) -> np.ndarray:
    """``collection.foreach_get(name)`` into a (len(collection),) int64 array."""
    out = np.empty(len(collection), dtype=np.int32)
    collection.foreach_get(name, out)
    return out.astype(np.int64)


def corner_normals(mesh) -> np.ndarray:
    """(C, 3) float64 shading normal of every corner (loop), custom split normals included.

    Blender 4.1 replaced ``calc_normals_split()`` + ``MeshLoop.normal`` by the
    always-up-to-date ``Mesh.corner_normals``.
    """
    if hasattr(mesh, "corner_normals"):
        return read_floats(mesh.corner_normals, "vector", 3)
    mesh.calc_normals_split()
    return read_floats(mesh.loops, "normal", 3)


def uv_coordinates(layer) -> np.ndarray:
    """(C, 2) float64 uv of every corner from a ``MeshUVLoopLayer``.

    Blender 3.5 added ``layer.uv`` (a plain float2 attribute) and deprecated the
    ``layer.data[i].uv`` path, which still exists alongside it.
    """
    if hasattr(layer, "uv"):
        return read_floats(layer.uv, "vector", 2)
    return read_floats(layer.data, "uv", 2)


def srgb_colors(attribute) -> np.ndarray:
    """(n, 3) float64 display (sRGB) colour of a colour attribute, in [0, 1].

    ``color_srgb`` gives the values a user paints and sees (and the OBJ exporter
    writes) for both byte and float attributes; ``color`` is scene-linear.
    """
    return read_floats(attribute.data, "color_srgb", 4)[:, :3]


def color_attribute(mesh, skip: str):
    """The mesh's active colour attribute, or the first other one when the active one is ``skip``.

    ``color_attributes.active_color`` (Blender 3.2+) replaced the legacy
    ``vertex_colors.active``. None when the mesh has no colour attribute but ``skip``.
    """
    active = mesh.color_attributes.active_color
    if active is not None and active.name != skip:
        return active
    return next((a for a in mesh.color_attributes if a.name != skip), None)


def material_node_tree(material):
    """The node tree a material renders with, or None.

    Blender 5.0 made every material a node material and deprecated
    ``Material.use_nodes``; before, a material with ``use_nodes`` off ignores
    its tree.
    """
    if material is None or material.node_tree is None:
        return None
    if version() < (5, 0, 0) and not material.use_nodes:
        return None
    return material.node_tree
