"""Which images a Blender material reads through which uv: its node tree, walked from the output.

The material's Principled BSDF is the first one upstream of the active Material Output's
Surface. Every Image Texture node upstream of one of its inputs is a texture of the role
design.md gives it ("Textures by role"): ``base colour`` under Base Color, ``normal`` under a
Normal Map node (or straight into Normal), ``height`` under a Bump node's Height, ``scalar``
under every other input. An image reached under several inputs takes the first role of
:data:`affinity.loaders.texturemaps.ROLES`. Its uv map is the one a UV Map node upstream of its
Vector names, else the mesh's active render uv map (what Blender renders an unlinked Vector
with); a Mapping node of type Point between them becomes the map's scale, offset and rotation
(about z). Anything else feeding Vector (generated or object coordinates, a linked or tilted
Mapping) does not read the uv: such an image is listed with ``unread`` saying why.

``bpy`` is not imported: the functions read the node objects they are given.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..loaders.texturemaps import ROLES
from . import compat

#: The role of an image upstream of a Principled BSDF input with this name (others: ``scalar``).
ROLE_OF_INPUT = {"Base Color": "base colour", "Normal": "normal"}


@dataclass(frozen=True, eq=False)
class ImageUse:
    """One Image Texture node a material's BSDF reads.

    Attributes
    ----------
    image : bpy.types.Image
    node : the Image Texture node's name
    role : ``"base colour"``, ``"normal"``, ``"height"`` or ``"scalar"``
    uv_map : the uv map it reads ("" for the mesh's active render uv map)
    extension, interpolation : the node's (``"REPEAT"``, ``"EXTEND"``, ``"CLIP"``, ``"MIRROR"``;
        ``"Linear"``, ``"Closest"``, ``"Cubic"``, ``"Smart"``)
    scale, offset, rotation : a Mapping node's transform of the uv (rotation in degrees about z)
    unread : why the uv cannot be followed to a uv map, else None
    """

    image: object
    node: str
    role: str
    uv_map: str = ""
    extension: str = "REPEAT"
    interpolation: str = "Linear"
    scale: tuple[float, float] = (1.0, 1.0)
    offset: tuple[float, float] = (0.0, 0.0)
    rotation: float = 0.0
    unread: str | None = None


def principled_bsdf(material):
    """The Principled BSDF node upstream of the material's active output's Surface, or None."""
    tree = compat.material_node_tree(material)
    if tree is None:
        return None
    output = next((tree.get_output_node(target) for target in ("ALL", "EEVEE", "CYCLES")
                   if tree.get_output_node(target) is not None), None)
    if output is None:
        return None
    return next(iter(_upstream_nodes(output.inputs["Surface"], "BSDF_PRINCIPLED")), None)


def material_images(material) -> list[ImageUse]:
    """Every Image Texture node with an image that the material's Principled BSDF reads, with its role,
    in the order of :data:`ROLES` (within a role, the BSDF's inputs in order, breadth first)."""
    bsdf = principled_bsdf(material)
    if bsdf is None:
        return []
    found: dict[str, ImageUse] = {}
    for socket in bsdf.inputs:
        role = ROLE_OF_INPUT.get(socket.name, "scalar")
        for node, node_role in _image_nodes(socket, role):
            known = found.get(node.name)
            if known is None or ROLES.index(node_role) < ROLES.index(known.role):
                found[node.name] = _use(node, node_role)
    return sorted(found.values(), key=lambda use: ROLES.index(use.role))


def _image_nodes(socket, role: str):
    """(node, role) of every Image Texture node with an image upstream of ``socket``, breadth first, a
    Normal Map node turning the role below it into ``normal`` and a Bump node's Height into ``height``."""
    queue = [(link.from_node, role) for link in socket.links]
    seen = set()
    while queue:
        node, role = queue.pop(0)
        if node.name in seen:
            continue
        seen.add(node.name)
        if node.type == "TEX_IMAGE":
            if node.image is not None:
                yield node, role
            continue  # what feeds its Vector is its uv, not a texture of the BSDF
        for parent in node.inputs:
            below = ("normal" if node.type == "NORMAL_MAP"
                     else "height" if node.type == "BUMP" and parent.name == "Height" else role)
            queue.extend((link.from_node, below) for link in parent.links)


def _upstream_nodes(socket, node_type: str):
    """The nodes of ``node_type`` upstream of ``socket``, breadth first."""
    queue = [link.from_node for link in socket.links]
    seen = set()
    while queue:
        node = queue.pop(0)
        if node.name in seen:
            continue
        seen.add(node.name)
        if node.type == node_type:
            yield node
        queue.extend(link.from_node for s in node.inputs for link in s.links)


def _use(node, role: str) -> ImageUse:
    """The :class:`ImageUse` of Image Texture ``node``: its uv followed up its Vector input."""
    use = {"image": node.image, "node": node.name, "role": role, "extension": node.extension,
           "interpolation": node.interpolation}
    links = node.inputs["Vector"].links
    source = links[0].from_node if links else None
    if source is not None and source.type == "MAPPING":
        mapping = source
        transform, why = _mapping_transform(mapping)
        if why is not None:
            return ImageUse(**use, unread=why)
        use.update(transform)
        links = mapping.inputs["Vector"].links
        source = links[0].from_node if links else None
        if source is None:
            return ImageUse(**use, unread=f"its Mapping node {mapping.name!r} has no uv input")
    if source is None:
        return ImageUse(**use)
    if source.type == "UVMAP":
        return ImageUse(**use, uv_map=source.uv_map)
    if source.type == "TEX_COORD" and links[0].from_socket.name == "UV":
        return ImageUse(**use)
    return ImageUse(**use, unread=f"its Vector comes from {source.name!r}, not a uv map")


def _mapping_transform(mapping) -> tuple[dict, str | None]:
    """The scale, offset and rotation (degrees) of a Mapping node of type Point, or why it is not read."""
    if mapping.vector_type != "POINT":
        return {}, f"its Mapping node {mapping.name!r} is of type {mapping.vector_type.title()}, not Point"
    sockets = {name: mapping.inputs[name] for name in ("Location", "Rotation", "Scale")}
    if any(socket.links for socket in sockets.values()):
        return {}, f"its Mapping node {mapping.name!r} has linked inputs"
    location, rotation, scale = (tuple(sockets[name].default_value) for name in ("Location", "Rotation", "Scale"))
    if rotation[0] or rotation[1]:
        return {}, f"its Mapping node {mapping.name!r} rotates about x or y"
    from math import degrees

    return {"scale": (scale[0], scale[1]), "offset": (location[0], location[1]), "rotation": degrees(rotation[2])}, None
