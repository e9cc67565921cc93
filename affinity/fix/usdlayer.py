"""A fixed USD stage as an override layer: it sublayers the input and overrides only the meshes it fixed.

The input layer is never touched. For each mesh prim with a refined or re-cut face the
layer holds an ``over`` with the prim's whole new topology (prims that compose one authored mesh
share one copy of it, written once in a ``class`` their ``over`` inherits: :func:`write_refined`) (``points``,
``faceVertexCounts``, ``faceVertexIndices``) and its attributes: the uv primvar the
check read (``st``, else the first ``texCoord2*``) and ``primvars:normals``, both
face-varying and indexed, and ``primvars:displayColor`` per vertex. Values go back from
the world space the check works in to the prim's own space (the inverse of its
local-to-world transform at the time read), and faces back to ``leftHanded`` order
where the prim has it. Other primvars and the index lists of holes, creases and corners
no longer match the new faces: they are blocked in the over, and the layer says so.
The stage's metadata (``upAxis``, ``metersPerUnit``, ``defaultPrim``, time codes) are
copied, since a sublayer's are not composed.
"""

from __future__ import annotations

import os

import numpy as np

from ..atomic import atomic_write
from ..mesh import Mesh
from .apply import Refined

#: Root-layer metadata a stage reads from its root layer only.
STAGE_METADATA = ("upAxis", "metersPerUnit", "defaultPrim", "startTimeCode", "endTimeCode", "timeCodesPerSecond",
                  "framesPerSecond")
#: Mesh attributes indexing faces or vertices, which the new topology invalidates.
TOPOLOGY_INDICES = ("holeIndices", "cornerIndices", "cornerSharpnesses", "creaseIndices", "creaseLengths",
                    "creaseSharpnesses")


def _array(type_name, values: np.ndarray):
    """A Vt array of the Sdf value type ``type_name`` from (n,) or (n, k) values."""
    from pxr import Sdf

    vt_type = type(Sdf.ValueTypeNames.Find(str(type_name)).defaultValue)
    scalar = vt_type.__name__.removesuffix("Array")[-1]  # IntArray, Vec2fArray, Vec3dArray, Vec2hArray
    dtype = {"t": np.int32, "d": np.float64, "h": np.float16}.get(scalar, np.float32)
    return vt_type.FromNumpy(np.ascontiguousarray(values, dtype=dtype))


def _set(prim_spec, name: str, type_name, value, interpolation: str | None = None) -> None:
    from pxr import Sdf

    spec = prim_spec.attributes.get(name) or Sdf.AttributeSpec(prim_spec, name, type_name)
    spec.default = value
    if interpolation:
        spec.SetInfo("interpolation", interpolation)


def _indexed(values: np.ndarray, index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The values the corners use, once each, and each corner's index into them."""
    used, local = np.unique(index, return_inverse=True)
    return values[used], local.reshape(-1)


def write_override_layer(path: str, out: str, mesh: Mesh, refined: Refined, header: str) -> list[str]:
    """Write the override layer of ``refined`` (the fix of ``mesh``, read from the stage ``path``) to ``out``;
    returns the notes on the meshes whose subdivided surface changes (:func:`subdivided_notes`)."""
    from pxr import Sdf, Usd

    from ..loaders.usddiagnostics import captured_diagnostics

    with captured_diagnostics("", []):  # said once already, when the stage was read for the plan
        stage = Usd.Stage.Open(os.fspath(path))
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.documentation = header
    source_root = stage.GetRootLayer()
    for key in STAGE_METADATA:
        if source_root.pseudoRoot.HasInfo(key):
            layer.pseudoRoot.SetInfo(key, source_root.pseudoRoot.GetInfo(key))
    layer.subLayerPaths.append(os.path.relpath(os.path.abspath(path), os.path.dirname(os.path.abspath(out))))
    blocked = write_refined(layer, stage, mesh, refined)
    if blocked:
        layer.documentation = f"{header}; blocked (they indexed the old faces): {', '.join(blocked)}"
    text = layer.ExportToString()
    if os.path.splitext(out)[1].lower() == ".usdc":
        _export_binary(text, out)
    else:
        with atomic_write(out) as f:
            f.write(text)
    return subdivided_notes(stage, mesh, refined, Usd.TimeCode.EarliestTime())


def write_refined(layer, stage, mesh: Mesh, refined: Refined, spec_path=None) -> list[str]:
    """Author the fixed prims of ``refined`` (the fix of ``mesh``, read from ``stage``) in ``layer``; returns the
    attributes blocked.

    A prim whose geometry no other fixed prim shares gets an ``over`` with its fixed geometry
    (:func:`override_prim`). Prims that compose one authored mesh (:func:`affinity.fix.twins.twin_faces`: the
    plan refines them alike) share one fixed copy: a ``class`` under :data:`FIXED_ROOT` holds it, written
    once from the first of them, and each prim's ``over`` inherits it (an inherit arc is stronger than the
    reference or payload that brings the authored mesh). ``spec_path`` maps a prim's path to its spec's in
    ``layer`` (an edit target's mapping; default: the same path).
    """
    from pxr import Sdf, Usd, UsdGeom

    from .twins import twin_faces

    spec_path = spec_path or (lambda path: path)
    time = Usd.TimeCode.EarliestTime()
    xforms = UsdGeom.XformCache(time)
    fixed = refined.mesh
    twins = twin_faces(mesh)
    starts = mesh.prim_face_start
    groups = np.unique(mesh.face_group[refined.replaced]).tolist()
    owner = {g: g if twins is None else int(mesh.face_group[twins[starts[g]]]) for g in groups}
    shared = {o for o in owner.values() if sum(1 for g in groups if owner[g] == o) > 1}
    blocked, classes = [], {}
    for group in groups:
        prim = stage.GetPrimAtPath(mesh.group_names[group])
        path = spec_path(prim.GetPath())
        if owner[group] not in shared:
            blocked += override_prim(layer, path, prim, fixed, group, time, xforms)
            continue
        if owner[group] not in classes:
            classes[owner[group]] = _fixed_class(layer, mesh.prim_sources[group])
            blocked += override_prim(layer, classes[owner[group]], prim, fixed, group, time, xforms)
        Sdf.CreatePrimInLayer(layer, path).inheritPathList.Prepend(classes[owner[group]])
    return blocked


#: Where the fixed copies of shared geometry live in a fix's layer (an abstract class: never drawn).
FIXED_ROOT = "/AffinityFixed"


def _fixed_class(layer, source) -> object:
    """A new ``class`` spec under :data:`FIXED_ROOT` in ``layer`` for the authored mesh ``source`` (layer, prim
    path), named after them; its path."""
    from pxr import Sdf, Tf

    root = Sdf.CreatePrimInLayer(layer, FIXED_ROOT)
    root.specifier = Sdf.SpecifierClass
    stem = os.path.splitext(os.path.basename(source[0]))[0]
    name = Tf.MakeValidIdentifier(f"{stem}_{source[1].strip('/').replace('/', '_')}")
    path, k = root.path.AppendChild(name), 1
    while layer.GetPrimAtPath(path):
        k += 1
        path = root.path.AppendChild(f"{name}_{k}")
    spec = Sdf.CreatePrimInLayer(layer, path)
    spec.specifier = Sdf.SpecifierClass
    return path


def override_prim(layer, spec_path, prim, fixed: Mesh, group: int, time, xforms) -> list[str]:
    """Author the fixed geometry of mesh ``prim`` (group ``group`` of ``fixed``, in world space) as an ``over``
    at ``spec_path`` in ``layer`` (see the module docstring); returns the attributes it blocked.

    ``affinity fix`` writes each fixed prim to its override layer at the prim's path; the USD
    validators' fixer writes to the edit target's layer at the path it maps the prim to.
    """
    from pxr import Sdf, UsdGeom

    from ..loaders.usd import reversed_winding, uv_primvar_name

    faces = np.arange(fixed.prim_face_start[group], fixed.prim_face_start[group + 1])
    sizes = fixed.face_sizes[faces]
    corners = np.arange(fixed.face_start[faces[0]], fixed.face_start[faces[-1] + 1])
    usd_mesh = UsdGeom.Mesh(prim)
    if usd_mesh.GetOrientationAttr().Get(time) == UsdGeom.Tokens.leftHanded:
        corners = corners[reversed_winding(np.concatenate([[0], np.cumsum(sizes)]))]
    matrix = np.array(xforms.GetLocalToWorldTransform(prim))
    inverse = np.linalg.inv(matrix)
    used, vertex = np.unique(fixed.corner_vertex[corners], return_inverse=True)
    points = np.einsum("ij,jk->ik", fixed.positions[used], inverse[:3, :3]) + inverse[3, :3]
    spec = Sdf.CreatePrimInLayer(layer, spec_path)
    _set(spec, "points", usd_mesh.GetPointsAttr().GetTypeName(), _array("point3f[]", points))
    _set(spec, "faceVertexCounts", Sdf.ValueTypeNames.IntArray, _array("int[]", sizes))
    _set(spec, "faceVertexIndices", Sdf.ValueTypeNames.IntArray, _array("int[]", vertex.reshape(-1)))
    written, blocked = set(), []
    uv_name = uv_primvar_name(prim, time)
    if uv_name is not None and fixed.corner_texcoord is not None and (fixed.corner_texcoord[corners] >= 0).all():
        values, index = _indexed(fixed.texcoords, fixed.corner_texcoord[corners])
        name = uv_name if uv_name.startswith("primvars:") else f"primvars:{uv_name}"
        type_name = prim.GetAttribute(name).GetTypeName()
        _set(spec, name, type_name, _array(type_name, values), "faceVarying")
        _set(spec, name + ":indices", Sdf.ValueTypeNames.IntArray, _array("int[]", index))
        written |= {name, name + ":indices"}
    if fixed.corner_normal is not None and (fixed.corner_normal[corners] >= 0).all():
        values, index = _indexed(fixed.normals, fixed.corner_normal[corners])
        local = np.einsum("ij,kj->ik", values, matrix[:3, :3])  # inverse of the world normals' transform
        local /= np.linalg.norm(local, axis=1, keepdims=True)
        _set(spec, "primvars:normals", Sdf.ValueTypeNames.Normal3fArray, _array("normal3f[]", local),
             "faceVarying")
        _set(spec, "primvars:normals:indices", Sdf.ValueTypeNames.IntArray, _array("int[]", index))
        written |= {"primvars:normals", "primvars:normals:indices"}
    if fixed.colors is not None and not np.isnan(fixed.colors[used]).any():
        _set(spec, "primvars:displayColor", Sdf.ValueTypeNames.Color3fArray,
             _array("color3f[]", fixed.colors[used]), "vertex")
        written.add("primvars:displayColor")
        if prim.HasAttribute("primvars:displayColor:indices"):
            _set(spec, "primvars:displayColor:indices", Sdf.ValueTypeNames.IntArray, Sdf.ValueBlock())
    for attribute in prim.GetAttributes():
        name = attribute.GetName()
        varying = name.startswith("primvars:") and UsdGeom.Primvar(attribute).GetInterpolation() != "constant"
        if name not in written and attribute.HasAuthoredValue() and (
                varying or name in TOPOLOGY_INDICES or name == "normals"):
            _set(spec, name, attribute.GetTypeName(), Sdf.ValueBlock())
            blocked.append(f"{prim.GetPath()}.{name}")
    return blocked


def _export_binary(text: str, out: str) -> None:
    """Write the layer ``text`` as a crate file at ``out``, whole or not at all."""
    import tempfile

    from pxr import Sdf

    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(text)
    folder = os.path.dirname(os.path.abspath(out))
    handle, temporary = tempfile.mkstemp(dir=folder, prefix=".fix.", suffix=".usdc")
    os.close(handle)
    try:
        if not layer.Export(temporary):
            raise OSError(f"cannot write {out}")
        os.replace(temporary, out)
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)


def subdivided_notes(stage, mesh: Mesh, refined: Refined, time) -> list[str]:
    """One note per mesh prim of ``stage`` the fix changes whose ``subdivisionScheme`` (authored, or USD's
    default Catmull-Clark) subdivides: the fix refines its cage, so its subdivided surface changes."""
    from pxr import UsdGeom

    from ..loaders.usdlayers import SUBDIVIDED

    notes = []
    for group in np.unique(mesh.face_group[refined.replaced]).tolist():
        prim = stage.GetPrimAtPath(mesh.group_names[group])
        scheme = str(UsdGeom.Mesh(prim).GetSubdivisionSchemeAttr().Get(time)) if prim else ""
        if scheme in SUBDIVIDED:
            notes.append(f"{mesh.group_names[group]}: subdivisionScheme {scheme}: the fix refines the cage (what "
                         "the check's profile draws), so the subdivided surface of this mesh changes")
    return notes
