"""The textures a USD mesh prim's bound material reads through its uv primvar (design.md, "Textures by role").

Two kinds of material are read:

- UsdPreviewSurface networks: each input of the surface shader connected to a
  ``UsdUVTexture`` whose ``inputs:st`` comes from a ``UsdPrimvarReader_float2``
  naming the prim's uv primvar; the texture is ``inputs:file``, resolved against the
  layer that authored it (UDIM tokens kept);
- MaterialX documents a material prim references (``references = @look.mtlx@</...>``):
  usd-core cannot compose them, so the reference is followed at the Sdf level (the
  material prim's spec) and the ``.mtlx`` XML is read with ElementTree: the
  ``image`` and ``tiledimage`` nodes upstream of the surface shader's inputs, through
  node graphs and ``normalmap`` nodes, with ``fileprefix`` and ``tiledimage``'s
  ``uvtiling``/``uvoffset``.

The role of a texture is the shader input it feeds: :data:`ROLE_OF_INPUT`, else
``scalar``.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree

from .regular import SIDE_FILE_BUDGET, read_regular
from .texturemaps import TextureMap

#: Surface shader inputs by role (UsdPreviewSurface, standard_surface, open_pbr_surface, gltf_pbr).
ROLE_OF_INPUT = {
    "diffuseColor": "base colour", "base_color": "base colour", "baseColor": "base colour",
    "normal": "normal", "geometry_normal": "normal",
    "displacement": "height", "height": "height",
}  # fmt: skip
_IMAGE_NODES = ("image", "tiledimage")


def prim_material_maps(prim, uv_primvar: str | None, all_variants: bool = False) -> tuple[str | None,
                                                                                         list[TextureMap]]:
    """The material bound to ``prim`` (its path; with ``all_variants``, the paths of every variant's binding joined
    by `` | ``) and the textures it reads through the primvar ``uv_primvar`` (None: ``st``); (None, []) when no
    material is bound."""
    paths = bound_material_paths(prim, all_variants)
    if not paths:
        return None, []
    maps = []
    for path in paths:
        maps += [found for found in _material_maps_at(prim.GetStage(), path, uv_primvar or "st") if found not in maps]
    return " | ".join(map(str, paths)), maps


def bound_material_paths(prim, all_variants: bool = False) -> list:
    """The ``Sdf.Path`` of the material bound to ``prim`` (any purpose: all-purpose, then ``full``, then
    ``preview``), whether or not a prim exists there; with ``all_variants`` then the paths the bindings of the
    variants not selected name (:func:`variant_binding_paths`). Empty when nothing is bound."""
    from pxr import UsdShade

    api = UsdShade.MaterialBindingAPI(prim)
    paths = []
    for purpose in (UsdShade.Tokens.allPurpose, UsdShade.Tokens.full, UsdShade.Tokens.preview):
        material, relationship = api.ComputeBoundMaterial(purpose)
        targets = [material.GetPath()] if material else relationship.GetTargets() if relationship else []
        if targets:
            paths.append(targets[0])
            break
    if all_variants:
        paths += [path for path in variant_binding_paths(prim) if path not in paths]
    return paths


def variant_binding_paths(prim) -> list:
    """The material paths the ``material:binding`` relationships of ``prim`` name inside every variant of its
    ancestors' (and its own) variant sets, the selected ones included, read from the Sdf specs and mapped to
    the stage's namespace (a target under the spec's root prim moves to the composed prim's path)."""
    from pxr import Sdf

    found = []
    ancestor = prim
    while ancestor and not ancestor.IsPseudoRoot():
        below = prim.GetPath().MakeRelativePath(ancestor.GetPath())
        for spec in ancestor.GetPrimStack():
            if spec.path.ContainsPrimVariantSelection():
                continue
            for variant_set in spec.variantSets.values():
                for variant in variant_set.variants.values():
                    inside = variant.primSpec.path if below.pathString == "." else \
                        variant.primSpec.path.AppendPath(below)
                    relationship = spec.layer.GetRelationshipAtPath(inside.AppendProperty("material:binding"))
                    if relationship is None:
                        continue
                    for target in relationship.targetPathList.GetAddedOrExplicitItems():
                        mapped = target.ReplacePrefix(spec.path, ancestor.GetPath()) if target.HasPrefix(spec.path) \
                            else target
                        if mapped not in found:
                            found.append(Sdf.Path(mapped))
        ancestor = ancestor.GetParent()
    return found


def _material_maps_at(stage, path, uv_primvar: str) -> list[TextureMap]:
    """The textures of the material at ``path`` on ``stage``: its UsdPreviewSurface network, else the MaterialX
    document it references; where no prim is there, the MaterialX document an ancestor's uncomposable ``.mtlx``
    reference names (:func:`ancestor_materialx_maps`)."""
    from pxr import UsdShade

    material = UsdShade.Material(stage.GetPrimAtPath(path))
    if material:
        return preview_surface_maps(material, uv_primvar) or materialx_maps(material.GetPrim())
    return ancestor_materialx_maps(stage, path)


def ancestor_materialx_maps(stage, path) -> list[TextureMap]:
    """The textures of the material at ``path`` that does not exist on ``stage`` because an ancestor's reference
    to a ``.mtlx`` document cannot compose (design.md, Clarifications): the nearest ancestor prim with such a
    reference (``/A/Materials`` referencing ``@x.mtlx@</MaterialX/Materials>``) maps ``path``
    (``/A/Materials/M_X``) into the document (``/MaterialX/Materials/M_X``), whose last name is the
    ``surfacematerial`` read."""
    ancestor = path.GetParentPath()
    while not ancestor.IsAbsoluteRootPath() and not ancestor.isEmpty:
        prim = stage.GetPrimAtPath(ancestor)
        reference = _mtlx_reference(prim) if prim else None
        if reference is not None:
            document, target = reference
            return mtlx_document_maps(document, path.ReplacePrefix(ancestor, target).name)
        ancestor = ancestor.GetParentPath()
    return []


def preview_surface_maps(material, uv_primvar: str) -> list[TextureMap]:
    """The ``UsdUVTexture`` files feeding the material's UsdPreviewSurface, by the input they feed."""
    source = material.ComputeSurfaceSource()
    shader = source[0] if source else None
    if not shader or shader.GetIdAttr().Get() != "UsdPreviewSurface":
        return []
    maps = []
    for shader_input in shader.GetInputs():
        for texture in _upstream_textures(shader_input):
            varname, transform = _st_source(texture)
            if varname not in (None, uv_primvar):
                continue  # the texture reads another uv set
            file_input = texture.GetInput("file")
            asset = file_input.Get() if file_input else None
            if not asset or not asset.path:
                continue
            maps.append(TextureMap(role=ROLE_OF_INPUT.get(shader_input.GetBaseName(), "scalar"),
                                   path=_resolved(file_input.GetAttr(), asset), name=asset.path,
                                   source=f"UsdUVTexture {texture.GetPath()}",
                                   wrap=tuple(_wrap(USD_WRAPS, _input_value(texture, name))
                                              for name in ("wrapS", "wrapT")),
                                   **transform))
    return maps


def _upstream_textures(shader_input) -> list:
    """The ``UsdUVTexture`` shaders a shader input is connected to, directly."""
    from pxr import UsdShade

    found = []
    for info in shader_input.GetConnectedSources()[0]:
        shader = UsdShade.Shader(info.source.GetPrim())
        if shader and shader.GetIdAttr().Get() == "UsdUVTexture":
            found.append(shader)
    return found


def _st_source(texture) -> tuple[str | None, dict]:
    """The primvar a ``UsdUVTexture``'s ``st`` is read from (its primvar reader's ``varname``; None when
    unconnected) and the ``UsdTransform2d`` between them as :class:`TextureMap` fields (``scale``,
    ``rotation``, ``offset``; none when there is no transform)."""
    transform: dict = {}
    shader = _connected_shader(texture.GetInput("st"))
    if shader is not None and shader.GetIdAttr().Get() == "UsdTransform2d":
        # UsdPreviewSurface: result = rotate(in * scale, rotation degrees) + translation.
        scale, rotation, translation = (_input_value(shader, name) for name in ("scale", "rotation", "translation"))
        transform = {"scale": (1.0, 1.0) if scale is None else (float(scale[0]), float(scale[1])),
                     "rotation": 0.0 if rotation is None else float(rotation),
                     "offset": (0.0, 0.0) if translation is None else (float(translation[0]), float(translation[1]))}
        shader = _connected_shader(shader.GetInput("in"))
    varname = shader.GetInput("varname") if shader is not None else None
    if not varname or varname.Get() is None:
        return None, transform
    return str(varname.Get()), transform


def _connected_shader(shader_input):
    """The shader an input is connected to (the first source), None when unconnected."""
    from pxr import UsdShade

    if not shader_input:
        return None
    for info in shader_input.GetConnectedSources()[0]:
        shader = UsdShade.Shader(info.source.GetPrim())
        if shader:
            return shader
    return None


def _input_value(shader, name: str):
    """The authored value of a shader input, None when it has none (the input's fallback then holds)."""
    shader_input = shader.GetInput(name)
    return shader_input.Get() if shader_input else None


def _resolved(attribute, asset) -> str:
    """An asset path's file: the resolver's answer, else the authored path against the folder of the layer
    that authored it (UDIM paths do not resolve)."""
    if asset.resolvedPath:
        return os.path.normpath(asset.resolvedPath)
    layer = attribute.GetPropertyStack()[0].layer if attribute.GetPropertyStack() else None
    folder = os.path.dirname(layer.realPath) if layer is not None and layer.realPath else ""
    return os.path.normpath(os.path.join(folder, asset.path))


def materialx_maps(material_prim) -> list[TextureMap]:
    """The textures of the MaterialX material a material prim references (the first ``.mtlx`` reference
    of its prim specs), read from the document's XML."""
    reference = _mtlx_reference(material_prim)
    if reference is None:
        return []
    document, target = reference
    return mtlx_document_maps(document, target.name or None)


def _mtlx_reference(prim) -> tuple[str, object] | None:
    """(document path, prim path inside it) of the first ``.mtlx`` reference of ``prim``'s specs; None when it
    has none."""
    for spec in prim.GetPrimStack():
        for reference in spec.referenceList.GetAddedOrExplicitItems():
            if reference.assetPath.lower().endswith(".mtlx"):
                document = spec.layer.ComputeAbsolutePath(reference.assetPath)
                if spec.layer.realPath and not os.path.isabs(document):
                    document = os.path.join(os.path.dirname(spec.layer.realPath), reference.assetPath)
                return document, reference.primPath
    return None


def mtlx_document_maps(path: str, material: str | None = None, every: bool = False) -> list[TextureMap]:
    """The image files feeding the surface shader of ``material`` (a ``surfacematerial`` name; None: the
    first; with ``every``, of every material) in the MaterialX document ``path``; empty when it cannot be
    read."""
    try:
        root = ElementTree.fromstring(read_regular(path, SIDE_FILE_BUDGET))  # a FIFO would block for good
    except (OSError, ElementTree.ParseError):
        return []
    nodes = _named_nodes(root)
    materials = [n for n in root.iter("surfacematerial") if material in (None, n.get("name"))]
    shaders = [_upstream(nodes, m.find("input[@name='surfaceshader']")) for m in materials[: None if every else 1]]
    folder = os.path.dirname(os.path.abspath(path))
    maps = []
    for shader_input in (i for shader in shaders if shader is not None for i in shader.findall("input")):
        role = ROLE_OF_INPUT.get(shader_input.get("name"), "scalar")
        for image in _images_upstream(nodes, shader_input):
            file_input = image.find("input[@name='file']")
            name = file_input.get("value") if file_input is not None else None
            if not name:
                continue
            name = _file_prefix(image, nodes, root.get("fileprefix", "")) + name
            scale, offset = _tiling(image)
            maps.append(TextureMap(role=role, path=os.path.normpath(os.path.join(folder, name)), name=name,
                                   source=f"MaterialX {image.tag} {image.get('name')} ({os.path.basename(path)})",
                                   scale=scale, offset=offset,
                                   wrap=tuple(_wrap(MATERIALX_WRAPS, _value(image, name))
                                              for name in ("uaddressmode", "vaddressmode"))))
    return maps


#: Wrap modes (:mod:`affinity.textures.wrapping`) by UsdUVTexture ``wrapS``/``wrapT`` token (``useMetadata``,
#: the file's own, and the fallback: repeat) and by MaterialX ``uaddressmode``/``vaddressmode`` (``constant``
#: reads the node's default outside, black unless set).
USD_WRAPS = {"repeat": "repeat", "mirror": "mirror", "clamp": "clamp", "black": "black"}
MATERIALX_WRAPS = {"periodic": "repeat", "mirror": "mirror", "clamp": "clamp", "constant": "black"}


def _wrap(modes: dict, authored) -> str:
    """The wrap mode of an authored token (None or an unknown one: repeat)."""
    return modes.get(str(authored) if authored is not None else "", "repeat")


def _value(image, name: str) -> str | None:
    """The ``value`` of an image node's input ``name``; None when it has none."""
    element = image.find(f"input[@name='{name}']")
    return None if element is None else element.get("value")


def _named_nodes(root) -> dict:
    """Every element with a name, by ``name`` and by ``graph/name`` inside node graphs; parents remembered."""
    nodes = {}
    for element in root:
        nodes[element.get("name")] = element
        if element.tag == "nodegraph":
            for child in element:
                nodes[f"{element.get('name')}/{child.get('name')}"] = child
                child.set("_graph", element.get("name"))
    return nodes


def _upstream(nodes: dict, connection, graph: str | None = None):
    """The node an ``input`` or ``output`` element (inside node graph ``graph``, None: at the top) is connected
    to, through node graph outputs."""
    if connection is None:
        return None
    if connection.get("nodename"):
        name = connection.get("nodename")
        return nodes.get(f"{graph}/{name}") if graph else nodes.get(name)
    if connection.get("nodegraph"):
        inner = connection.get("nodegraph")
        return _upstream(nodes, nodes.get(f"{inner}/{connection.get('output') or 'out'}"), inner)
    return None


def _images_upstream(nodes: dict, connection, graph: str | None = None, depth: int = 0) -> list:
    """The image nodes upstream of a connection (through normalmap and other nodes, at most 16 deep)."""
    node = _upstream(nodes, connection, graph)
    if node is None or depth > 16:
        return []
    if node.tag in _IMAGE_NODES:
        return [node]
    return [image for child in node.findall("input")
            for image in _images_upstream(nodes, child, node.get("_graph"), depth + 1)]


def _file_prefix(image, nodes: dict, document_prefix: str) -> str:
    """The ``fileprefix`` in force at an image node: its own, else its node graph's, else the document's."""
    graph = nodes.get(image.get("_graph")) if image.get("_graph") else None
    for element in (image, graph):
        if element is not None and element.get("fileprefix") is not None:
            return element.get("fileprefix")
    return document_prefix


def _tiling(image) -> tuple[tuple[float, float], tuple[float, float]]:
    """A ``tiledimage``'s scale and offset: MaterialX's ``ND_tiledimage`` graph reads the image at
    ``uv * uvtiling - uvoffset``, so (``uvtiling``, ``-uvoffset``)."""
    def vector(name, default):
        element = image.find(f"input[@name='{name}']")
        if element is None or not element.get("value"):
            return default
        a, b = (float(x) for x in element.get("value").split(","))
        return a, b

    if image.tag != "tiledimage":
        return (1.0, 1.0), (0.0, 0.0)
    offset = vector("uvoffset", (0.0, 0.0))
    return vector("uvtiling", (1.0, 1.0)), (-offset[0], -offset[1])
