"""The Fix button: refine an object's flagged faces in place, as ``affinity fix`` refines a file's.

The object is converted and planned exactly as the command line does
(:func:`affinity.fix.plan_fix` on the :mod:`.convert` mesh, the panel's settings), and
the result is written back through ``bmesh``: the replaced polygons are deleted and the
new ones added with the replaced polygon as their example (material, smooth flag and
custom face data carried over), their corners' uv set from the refinement. Vertices
keep their indices; new ones are appended. bmesh adds one vertex and one face per call:
those loops run over what the selection adds, never over the whole mesh.
"""

from __future__ import annotations

import numpy as np

from . import compat
from .convert import polygon_corners


def fix_object(obj, faces: np.ndarray | None = None, level: str = "warning", max_refine: int = 8, **options):
    """Refine the faces of ``obj`` that Q101-Q103 flag at or above ``level`` (only ``faces``, polygon
    indices, when given); ``options`` are :func:`.check.check_object`'s. Returns the
    :class:`affinity.fix.FixPlan`, faces numbered as the polygons were before the fix."""
    from ..fix import FixSettings, plan_fix, refine_mesh
    from ..textures.held import holding
    from .check import check_object

    checked = check_object(obj, **options)
    mesh = checked.conversion.mesh
    chosen = None if faces is None else np.asarray(faces, dtype=np.int64)
    with holding(checked.conversion.textures.held):  # the fix lints through the images, as the check did
        plan = plan_fix(mesh, FixSettings(lint=checked.settings, level=level, max_refine=max_refine, faces=chosen))
        refined = None if plan.empty else refine_mesh(mesh, plan)
    if refined is not None:
        _write_back(obj, mesh, refined, checked.conversion.uv_layer)
    return plan


def _write_back(obj, mesh, refined, uv_layer: str | None) -> None:
    """Replace ``refined.replaced`` polygons of ``obj.data`` by the new faces of ``refined.mesh``."""
    import bmesh

    me = obj.data
    fixed = refined.mesh
    _, loops = polygon_corners(me)
    blender_vertex = np.empty(len(mesh.positions), dtype=np.int64)  # a converted vertex -> its Blender vertex
    blender_vertex[mesh.corner_vertex] = compat.read_ints(me.loops, "vertex_index")[loops]
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    world = fixed.positions[len(mesh.positions):]
    local = (world - matrix[:3, 3]) @ np.linalg.inv(matrix[:3, :3]).T
    # points made twice (a vertex split by a corner colour) are one Blender vertex
    unique, which = np.unique(local, axis=0, return_inverse=True)
    vertex_of = np.concatenate([blender_vertex, len(me.vertices) + which.reshape(-1)])

    bm = bmesh.new()
    try:
        bm.from_mesh(me)
        for co in unique.tolist():
            bm.verts.new(co)
        bm.verts.ensure_lookup_table()
        bm.faces.ensure_lookup_table()
        uv = (bm.loops.layers.uv.get(uv_layer) if uv_layer else None) if fixed.texcoords is not None else None
        added = np.flatnonzero(refined.added)
        examples = [bm.faces[f] for f in refined.replaced.tolist()]
        example_of = dict(zip(refined.replaced.tolist(), examples))
        for face, source in zip(added.tolist(), refined.source[added].tolist()):
            corners = range(fixed.face_start[face], fixed.face_start[face + 1])
            new = bm.faces.new([bm.verts[vertex_of[fixed.corner_vertex[c]]] for c in corners], example_of[source])
            if uv is not None:
                for loop, c in zip(new.loops, corners):
                    loop[uv].uv = fixed.texcoords[fixed.corner_texcoord[c]].tolist()
        bmesh.ops.delete(bm, geom=examples, context="FACES_ONLY")
        bm.to_mesh(me)
    finally:
        bm.free()
    me.update()
