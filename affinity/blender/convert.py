"""A Blender mesh object as the project's :class:`affinity.mesh.Mesh`, read in memory.

Everything is read with ``foreach_get`` into NumPy buffers (no Python object
per vertex, corner or face) and no file is written. Faces stay as Blender's
polygons, in Blender's order, so face ``f`` of the result is polygon ``f`` (the
order the OBJ exporter writes them in). Per-corner data (uv, shading normals)
stays per corner, as OBJ's ``vt``/``vn`` indices keep it; a colour attribute
on the corner domain splits a vertex where its corners disagree, because
:class:`~affinity.mesh.Mesh` stores colours per position vertex.

With ``evaluated=True`` the mesh is the one the modifiers produce. Blender
keeps an "original index" for every evaluated polygon but does not expose it
to Python, so the conversion stores its own: an integer face attribute
(:data:`ORIGINAL_FACE`, polygon index + 1) is added to the original mesh for
the duration of the evaluation and removed after. Modifiers carry generic
attributes along (a subdivided face keeps its parent's value); a face whose
value is 0 was made by a modifier from no original face, and a modifier that
drops attributes leaves no mapping at all (``original_face`` is None), which
turns selection off.

``bpy`` itself is only imported inside the functions that need the running
Blender (depsgraph access). Textures are read from the materials' images by
:mod:`.texturemaps`, through Blender (:mod:`.images`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..mesh import Mesh
from . import compat
from .texturemaps import ObjectTextures, object_textures

#: Face attribute that carries original polygon indices (+ 1) through the modifier stack.
ORIGINAL_FACE = "affinity_original_face"
#: The extension's output: per-face error (float, face domain) and its picture (colour, corner
#: domain) for the viewport's Attribute colouring. The colours are never read back as vertex colours.
ERROR_ATTRIBUTE = "affinity_error"
ERROR_COLOR = "affinity_error_color"


@dataclass(eq=False)
class Conversion:
    """A converted object and what the panel needs to say about it.

    Attributes
    ----------
    mesh : Mesh
        One group, named after the object; positions and normals in world space.
    original_face : (F,) int64 or None
        The original polygon of every face of ``mesh`` (-1 where a modifier made a
        face from none); None when there is no mapping back to the original mesh.
    uv_layer : str or None
        The uv map that was read, None when the mesh has none.
    color_attribute : str or None
        The colour attribute that was read, None when there is none.
    textures : ObjectTextures
        The images the materials read through ``uv_layer``, held while the lint runs.
    notes : list of str
        What the conversion could not do, for the user.
    """

    mesh: Mesh
    original_face: np.ndarray | None
    uv_layer: str | None
    color_attribute: str | None
    textures: ObjectTextures
    notes: list[str] = field(default_factory=list)


def mesh_from_object(obj, evaluated: bool = False, uv_layer: str | None = None) -> Mesh:
    """The mesh of a Blender mesh object as a :class:`~affinity.mesh.Mesh`.

    Parameters
    ----------
    obj : bpy.types.Object of type ``"MESH"``
    evaluated : bool
        Read the mesh with its modifiers applied (see the module docstring for how
        its faces map back to the original polygons).
    uv_layer : str or None
        The uv map to read; None reads the active one.
    """
    return convert_object(obj, evaluated=evaluated, uv_layer=uv_layer).mesh


def convert_object(obj, evaluated: bool = False, uv_layer: str | None = None) -> Conversion:
    """:func:`mesh_from_object` with the face mapping, the layers read and notes."""
    if obj.type != "MESH":
        raise ValueError(f"{obj.name}: not a mesh object ({obj.type})")
    if obj.mode == "EDIT":
        obj.update_from_editmode()  # edit-mode changes reach obj.data only on a mode switch
    if uv_layer is not None and obj.data.uv_layers.get(uv_layer) is None:
        raise ValueError(f"{obj.name}: no uv map named {uv_layer!r}")
    if not evaluated:
        conversion = _convert(obj, obj.data, uv_layer)
        conversion.original_face = np.arange(conversion.mesh.n_faces, dtype=np.int64)
        return conversion
    return _convert_evaluated(obj, uv_layer)


def _convert_evaluated(obj, uv_layer: str | None) -> Conversion:
    import bpy

    original = obj.data
    tag = original.attributes.new(ORIGINAL_FACE, "INT", "FACE")
    try:
        tag.data.foreach_set("value", np.arange(1, len(original.polygons) + 1, dtype=np.int32))
        original.update()
        depsgraph = bpy.context.evaluated_depsgraph_get()
        evaluated = obj.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh(preserve_all_data_layers=True, depsgraph=depsgraph)
        try:
            conversion = _convert(obj, mesh, uv_layer)
            carried = mesh.attributes.get(ORIGINAL_FACE)
            if carried is not None and carried.domain == "FACE" and len(carried.data) == len(mesh.polygons):
                conversion.original_face = compat.read_ints(carried.data, "value") - 1
            else:
                conversion.notes.append(
                    "the modifiers do not keep face attributes, so findings cannot be mapped back "
                    "to the original faces: selection is off"
                )
        finally:
            evaluated.to_mesh_clear()
    finally:
        original.attributes.remove(original.attributes[ORIGINAL_FACE])
        original.update()
    return conversion


def _convert(obj, me, uv_layer: str | None) -> Conversion:
    """Read mesh data ``me`` (the object's own or an evaluated copy) of ``obj``."""
    matrix = np.array(obj.matrix_world, dtype=np.float64)  # (4, 4), column vectors
    linear, offset = matrix[:3, :3], matrix[:3, 3]

    positions = compat.read_floats(me.vertices, "co", 3) @ linear.T + offset
    face_start, loops = polygon_corners(me)
    corner_vertex = compat.read_ints(me.loops, "vertex_index")[loops]
    n_faces, n_corners = len(face_start) - 1, len(loops)

    # Normals are covectors: they map with the inverse transpose (lint rescales them to unit length).
    normals = compat.corner_normals(me)[loops] @ np.linalg.inv(linear)

    layer = me.uv_layers.get(uv_layer) if uv_layer is not None else me.uv_layers.active
    texcoords = compat.uv_coordinates(layer)[loops] if layer is not None else None

    colors, color_name = None, None
    color = compat.color_attribute(me, skip=ERROR_COLOR)
    if color is not None:
        color_name = color.name
        rgb = compat.srgb_colors(color)
        if color.domain == "CORNER":
            positions, corner_vertex, colors = _split_by_corner_color(positions, corner_vertex, rgb[loops])
        else:
            colors = rgb

    materials = [slot.material for slot in obj.material_slots]
    names = [m.name if m is not None else "" for m in materials]
    render_layer = next((uv.name for uv in me.uv_layers if uv.active_render), None)
    textures = object_textures(materials, layer.name if layer is not None else None, render_layer, texcoords)
    mesh = Mesh(
        path=obj.name,
        positions=positions,
        face_start=face_start,
        corner_vertex=corner_vertex,
        face_line=np.zeros(n_faces, dtype=np.int64),
        texcoords=texcoords,
        corner_texcoord=None if texcoords is None else np.arange(n_corners, dtype=np.int64),
        normals=normals,
        corner_normal=np.arange(n_corners, dtype=np.int64),
        colors=colors,
        group_names=[obj.name],
        face_group=np.zeros(n_faces, dtype=np.int32),
        material_names=names,
        face_material=compat.read_ints(me.polygons, "material_index").astype(np.int32) if names
        else np.full(n_faces, -1, dtype=np.int32),
        material_textures=textures.grid_maps,
        material_maps=textures.maps,
    )
    return Conversion(mesh, None, layer.name if layer is not None else None, color_name, textures,
                      list(textures.notes))


def polygon_corners(me) -> tuple[np.ndarray, np.ndarray]:
    """Corner layout of a ``bpy.types.Mesh``'s polygons, in polygon order.

    Returns
    -------
    face_start : (F + 1,) int64
        Polygon ``f`` owns corners ``face_start[f]:face_start[f + 1]``.
    loops : (C,) int64
        The Blender loop of every corner (the identity for every mesh Blender
        makes, which stores a polygon's loops contiguously and in order).
    """
    loop_start = compat.read_ints(me.polygons, "loop_start")
    loop_total = compat.read_ints(me.polygons, "loop_total")
    face_start = np.concatenate([[0], np.cumsum(loop_total)]).astype(np.int64)
    loops = np.repeat(loop_start - face_start[:-1], loop_total) + np.arange(face_start[-1])
    return face_start, loops


def _split_by_corner_color(positions, corner_vertex, corner_rgb):
    """Give every distinct (vertex, colour) pair of the corners a vertex of its own.

    Parameters
    ----------
    positions : (V, 3) float64
    corner_vertex : (C,) int64
    corner_rgb : (C, 3) float64

    Returns
    -------
    positions : (V', 3) float64, colors : (V', 3) float64, corner_vertex : (C,) int64
    """
    keys = np.column_stack([corner_vertex.astype(np.float64), corner_rgb])
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    return positions[unique[:, 0].astype(np.int64)], inverse.reshape(-1).astype(np.int64), unique[:, 1:]
