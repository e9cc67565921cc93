"""The layers of a USD stage as files: what each names (sublayers, references, payloads,
textures), where a mesh's geometry is authored and whether it is a subdivision cage
(``pxr`` imported inside each function: without it a layer names nothing)."""

from __future__ import annotations

import os

from ..errors import MeshError
from .regular import not_regular


def _layer(path: str):
    """The Sdf layer at ``path``, None without ``pxr`` or when it cannot be opened."""
    try:
        from pxr import Sdf, Tf
    except ImportError:
        return None
    try:
        return Sdf.Layer.FindOrOpen(os.fspath(path))
    except Tf.ErrorException:
        return None


def layer_assets(path: str) -> list[tuple[str, str]]:
    """``(asset, absolute path)`` of the sublayers, references and payloads the USD layer ``path``
    names, sorted by asset path (the resource role ``usd-asset``); none without ``pxr`` or when the
    layer cannot be opened."""
    layer = _layer(path)
    if layer is None:
        return []
    return [(asset, layer.ComputeAbsolutePath(asset)) for asset in sorted(layer.GetCompositionAssetDependencies())]


def texture_asset_paths(path: str) -> list[str]:
    """The files the asset-valued attributes of the USD layer ``path`` name (a ``UsdUVTexture``'s
    ``inputs:file``), resolved against the layer's folder, in path order; none without ``pxr`` or when the
    layer cannot be opened. The result cache follows them (a changed texture changes C)."""
    layer = _layer(path)
    if layer is None:
        return []
    from pxr import Sdf

    found = []

    def visit(spec_path) -> None:
        if not spec_path.IsPropertyPath():
            return
        spec = layer.GetAttributeAtPath(spec_path)
        value = spec.default if spec is not None and spec.typeName == Sdf.ValueTypeNames.Asset else None
        if isinstance(value, Sdf.AssetPath) and value.path:
            found.append(os.path.normpath(os.path.join(os.path.dirname(os.fspath(path)), value.path)))

    layer.Traverse(Sdf.Path.absoluteRootPath, visit)
    return sorted(set(found))


def asset_paths(path: str) -> list[str]:
    """The absolute paths of :func:`layer_assets`."""
    return [absolute for _, absolute in layer_assets(path)]


def regular_layers(path) -> tuple[list, bool]:
    """Every layer the stage at ``path`` composes (its sublayers, references and payloads, and
    theirs), opened with Sdf after a look at what each is, and whether that is all of them: False when
    a layer is missing or could not be opened (a packaged or resolver path, say), which is left to the
    stage to report. MeshError naming a layer that is a FIFO, socket or device, which pxr would read
    without end or wait on forever."""
    from pxr import Sdf, Tf

    layers, todo, seen, complete = [], [os.fspath(path)], set(), True  # the root as the stage names it: opened once
    while todo:
        layer_path = todo.pop()
        if layer_path in seen:
            continue
        seen.add(layer_path)
        try:
            reason = not_regular(os.stat(layer_path).st_mode)
        except (OSError, ValueError):
            complete = False
            continue
        if reason is not None:
            raise MeshError(path, 0, f"the layer {layer_path} {reason}")
        try:
            layer = Sdf.Layer.FindOrOpen(layer_path)
        except Tf.ErrorException:
            layer = None
        if layer is None:
            complete = False
            continue
        layers.append(layer)
        todo += [layer.ComputeAbsolutePath(asset) for asset in layer.GetCompositionAssetDependencies()]
    return layers, complete


def prim_type_names(layer) -> set[str]:
    """The type names of the prim specs of one Sdf ``layer``, those inside variants included (a
    variant can define a mesh), without composing anything: one look at each spec's path, O(specs)."""
    spec_paths = []
    layer.Traverse(layer.pseudoRoot.path, spec_paths.append)  # a builtin callback: no Python frame per spec
    prim_at = layer.GetPrimAtPath
    return {prim_at(spec_path).typeName for spec_path in spec_paths if spec_path.IsPrimPath()} - {""}


#: Prim types of a look: a layer that holds one (and no mesh) is a checked file with no findings, not a skip.
LOOK_TYPES = frozenset({"Material", "Shader", "NodeGraph"})


def holds_look(layer, type_names: set[str]) -> bool:
    """Whether the Sdf ``layer`` (whose prim specs have ``type_names``) holds a look: a prim of
    :data:`LOOK_TYPES`, a ``material:binding`` relationship (inside variants too) or a reference to a MaterialX
    document, as an asset's ``*_look.usd`` does (design.md, Clarifications)."""
    if type_names & LOOK_TYPES or any(asset.lower().endswith(".mtlx")
                                      for asset in layer.GetCompositionAssetDependencies()):
        return True
    spec_paths = []
    layer.Traverse(layer.pseudoRoot.path, spec_paths.append)
    return any(spec_path.IsPropertyPath() and spec_path.name.startswith("material:binding")
               for spec_path in spec_paths)


def may_hold_mesh(type_names: set[str]) -> bool:
    """Whether a prim of one of ``type_names`` may compose to a ``UsdGeom.Mesh``: a Mesh, a type derived
    from it, or a type usd-core does not know (a plug-in's schema, or one with ``fallbackPrimTypes``)."""
    from pxr import Usd, UsdGeom

    mesh = UsdGeom.Mesh._GetStaticTfType()
    types = (Usd.SchemaRegistry.GetTypeFromSchemaTypeName(name) for name in type_names)
    return any(schema.isUnknown or schema.IsA(mesh) for schema in types)


def geometry_source(prim, time) -> tuple[str, str] | None:
    """``(layer, prim path in that layer)`` where the mesh prim's ``points``, ``faceVertexCounts`` and
    ``faceVertexIndices`` are authored (the strongest opinion with a value), the layer named by its
    real path (its identifier when it has none, e.g. an anonymous layer); None when the three come
    from different places. Prims that reference one geometry layer share their source."""
    from pxr import UsdGeom

    usd_mesh = UsdGeom.Mesh(prim)
    sources = {_authored_at(attr, time) for attr in (usd_mesh.GetPointsAttr(), usd_mesh.GetFaceVertexCountsAttr(),
                                                     usd_mesh.GetFaceVertexIndicesAttr())}
    return sources.pop() if len(sources) == 1 else None


def _authored_at(attr, time) -> tuple[str, str] | None:
    """(layer, prim path) of the strongest spec of ``attr`` holding a default or time samples."""
    for spec in attr.GetPropertyStack(time):
        if spec.HasDefaultValue() or spec.layer.GetNumTimeSamplesForPath(spec.path):
            return spec.layer.realPath or spec.layer.identifier, str(spec.path.GetPrimPath())
    return None


#: Subdivision schemes a renderer may refine: the numbers of this tool are for the cage they start from.
SUBDIVIDED = ("catmullClark", "loop")


def subdivision_note(prims, time) -> str | None:
    """One note for the prims whose ``subdivisionScheme`` (authored, or USD's default Catmull-Clark)
    makes them subdivision surfaces; None when there are none."""
    from pxr import UsdGeom

    schemes = [str(UsdGeom.Mesh(prim).GetSubdivisionSchemeAttr().Get(time)) for prim in prims]
    count = sum(scheme in SUBDIVIDED for scheme in schemes)
    if not count:
        return None
    named = " or ".join(sorted({scheme for scheme in schemes if scheme in SUBDIVIDED}))
    return (f"{count} of {len(prims)} mesh prim{'s' * (len(prims) != 1)} subdivide{'s' * (count == 1)} "
            f"(subdivisionScheme {named}, "
            "authored or USD's default): the findings are for the cage, which is what Storm draws at its default "
            "complexity and what game engines draw")
