"""Write a mesh into a USD mesh prim, at an edit target: what the fixer leaves in the layer.

The mesh is in the prim's own space (:func:`affinity.loaders.usd.load_stage` with
``world=False``), corners in right-handed order. Written, as opinions in the edit
target's layer: ``points``, ``faceVertexCounts``, ``faceVertexIndices``,
``orientation = rightHanded`` where the prim was left-handed (the loader turned its
winding), ``extent``; the uv primvar (faceVarying, indexed), the normals (faceVarying,
as the prim authored them: ``primvars:normals`` indexed or the ``normals`` attribute)
and ``displayColor`` (vertex). A prim whose other data depends on the face order or
count cannot take a new topology: :func:`cannot_author` names what is in the way.
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh

#: Primvar interpolations that do not depend on the faces or points: kept as they are.
_FREE = ("constant",)
#: Attributes that number faces, corners or edges of the old topology.
_TOPOLOGY_BOUND = ("holeIndices", "cornerIndices", "creaseIndices", "creaseLengths")


def cannot_author(prim, time, uv_name: str | None) -> str | None:
    """Why a new topology cannot be written to ``prim`` (time-sampled points or topology, primvars
    this module does not rewrite, geometry subsets, holes, creases, corners); None when it can."""
    from pxr import UsdGeom

    usd_mesh = UsdGeom.Mesh(prim)
    for attr in (usd_mesh.GetPointsAttr(), usd_mesh.GetFaceVertexCountsAttr(), usd_mesh.GetFaceVertexIndicesAttr()):
        if attr.GetNumTimeSamples() > 1:
            return f"{attr.GetName()} is animated: refining one time sample would break the others"
    for name in _TOPOLOGY_BOUND:
        attr = prim.GetAttribute(name)
        if attr and attr.HasAuthoredValue() and len(attr.Get(time) or []):
            return f"{name} number the faces or corners of the current topology"
    if UsdGeom.Subset.GetAllGeomSubsets(UsdGeom.Imageable(prim)):
        return "GeomSubsets list faces of the current topology"
    rewritten = {uv_name, "primvars:normals", "primvars:displayColor"}
    for primvar in UsdGeom.PrimvarsAPI(prim).GetPrimvarsWithAuthoredValues():
        if primvar.GetInterpolation() not in _FREE and primvar.GetAttr().GetName() not in rewritten:
            return f"{primvar.GetAttr().GetName()} ({primvar.GetInterpolation()}) would not match the new faces"
    return None


def author_mesh(stage, prim_path: str, mesh: Mesh, edit_target, time, uv_name: str | None) -> None:
    """Write ``mesh`` (one prim's, in its own space) into the prim at ``prim_path`` through ``edit_target``.

    ``uv_name`` is the attribute name of the uv primvar the mesh's texture coordinates came from.
    """
    from pxr import Gf, Usd, UsdGeom, Vt

    prim = stage.GetPrimAtPath(prim_path)
    usd_mesh = UsdGeom.Mesh(prim)
    authored_normals = UsdGeom.PrimvarsAPI(prim).GetPrimvar("normals").HasAuthoredValue()
    with Usd.EditContext(stage, edit_target):
        usd_mesh.GetPointsAttr().Set(Vt.Vec3fArray.FromNumpy(mesh.positions.astype(np.float32)))
        usd_mesh.GetFaceVertexCountsAttr().Set(Vt.IntArray.FromNumpy(np.diff(mesh.face_start).astype(np.int32)))
        usd_mesh.GetFaceVertexIndicesAttr().Set(Vt.IntArray.FromNumpy(mesh.corner_vertex.astype(np.int32)))
        if usd_mesh.GetOrientationAttr().Get(time) == UsdGeom.Tokens.leftHanded:
            usd_mesh.GetOrientationAttr().Set(UsdGeom.Tokens.rightHanded)
        if usd_mesh.GetExtentAttr().HasAuthoredValue():
            low, high = mesh.positions.min(axis=0), mesh.positions.max(axis=0)
            usd_mesh.GetExtentAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*low.tolist()), Gf.Vec3f(*high.tolist())]))
        primvars = UsdGeom.PrimvarsAPI(prim)
        if mesh.texcoords is not None and uv_name is not None:
            _indexed(primvars.GetPrimvar(uv_name.removeprefix("primvars:")), mesh.texcoords, mesh.corner_texcoord,
                     Vt.Vec2fArray)
        if mesh.normals is not None:
            if authored_normals:
                _indexed(primvars.GetPrimvar("normals"), mesh.normals, mesh.corner_normal, Vt.Vec3fArray)
            else:
                usd_mesh.GetNormalsAttr().Set(Vt.Vec3fArray.FromNumpy(
                    mesh.normals[mesh.corner_normal].astype(np.float32)))
                usd_mesh.SetNormalsInterpolation(UsdGeom.Tokens.faceVarying)
        if mesh.colors is not None:
            color = primvars.GetPrimvar("displayColor")
            color.Set(Vt.Vec3fArray.FromNumpy(mesh.colors.astype(np.float32)))
            color.SetInterpolation(UsdGeom.Tokens.vertex)
            if color.IsIndexed():
                color.BlockIndices()


def _indexed(primvar, values: np.ndarray, corner_index: np.ndarray, array_type) -> None:
    """Set ``primvar`` faceVarying: ``values`` (n, k) float64, indexed by ``corner_index`` (C,) int64."""
    from pxr import UsdGeom, Vt

    primvar.Set(array_type.FromNumpy(values.astype(np.float32)))
    primvar.SetIndices(Vt.IntArray.FromNumpy(corner_index.astype(np.int32)))
    primvar.SetInterpolation(UsdGeom.Tokens.faceVarying)
