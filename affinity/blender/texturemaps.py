"""An object's materials as the lint's texture maps: :class:`~affinity.loaders.texturemaps.TextureMap` records
naming Blender images held in memory, as an OBJ's MTL names files.

Per material, every image its Principled BSDF reads (:func:`.materials.material_images`) through the uv
map being linted becomes a map of its role; its texels are Blender's (:func:`.images.held_textures`). An
image that reads another uv map, or whose uv cannot be followed, is left out with a note; so is one whose
texels cannot be read. Images with an extension other than Repeat, or an interpolation other than Linear,
are read as Repeat and Linear (the sampler of design.md's visible reading) with a note: for uv inside
[0, 1] the extension changes only the half texel at the image's border.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..loaders.texturemaps import TextureMap
from .images import UDIM_TOKEN, held_textures, image_key
from .materials import material_images


@dataclass(eq=False)
class ObjectTextures:
    """What an object's materials give the lint.

    Attributes
    ----------
    maps : material name -> its texture maps (``Mesh.material_maps``)
    grid_maps : material name -> the key of the map that sets its texel grid, the base colour's or the first
        (``Mesh.material_textures``: a mesh copied without its maps, as a fix's pieces are, keeps its unit)
    held : key -> DecodedTexture, to hold while the lint runs (:func:`affinity.textures.held.holding`)
    notes : what was left out or read otherwise, and why
    """

    maps: dict = field(default_factory=dict)
    grid_maps: dict = field(default_factory=dict)
    held: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def object_textures(materials, uv_layer: str | None, render_uv_layer: str | None) -> ObjectTextures:
    """The texture maps of ``materials`` (bpy.types.Material, None for an empty slot) read through the uv map
    ``uv_layer`` (None: the mesh has none, and nothing is read); ``render_uv_layer`` is the mesh's active
    render uv map, which an Image Texture with an unlinked Vector reads."""
    found = ObjectTextures()
    if uv_layer is None:
        return found
    uses = {material.name: material_images(material) for material in materials if material is not None}
    readable = []
    for material, images in uses.items():
        for use in images:
            where = f"{material}: image {use.image.name!r} ({use.role})"
            uv_map = use.uv_map or render_uv_layer
            if use.unread is not None:
                found.notes.append(f"{where} is not read: {use.unread}")
            elif uv_map != uv_layer:
                found.notes.append(f"{where} reads UV map {uv_map!r}, not the linted {uv_layer!r}: not read")
            else:
                readable.append((material, use))
    found.held, failed = held_textures(use.image for _, use in readable)
    found.notes.extend(failed)
    for material, use in readable:
        key = image_key(use.image)
        tile_prefix = key.split(UDIM_TOKEN)[0]  # a UDIM image's tiles are held under its key's head
        if key not in found.held and not (key.endswith(UDIM_TOKEN) and any(k.startswith(tile_prefix)
                                                                            for k in found.held)):
            continue
        ways = [f"extension {use.extension.title()}"] * (use.extension != "REPEAT") + \
               [f"interpolation {use.interpolation}"] * (use.interpolation != "Linear")
        if ways:
            found.notes.append(f"{material}: image {use.image.name!r} ({use.role}) has {' and '.join(ways)}: "
                               "read as Repeat and Linear")
        found.maps.setdefault(material, []).append(TextureMap(
            role=use.role, path=key, name=use.image.name, source=f"Image Texture {use.node!r}",
            scale=use.scale, offset=use.offset, rotation=use.rotation))
        found.grid_maps.setdefault(material, key)  # the base colour's, listed first, else the first role's
    return found
