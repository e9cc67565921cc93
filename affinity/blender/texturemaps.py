"""An object's materials as the lint's texture maps: :class:`~affinity.loaders.texturemaps.TextureMap` records
naming Blender images held in memory, as an OBJ's MTL names files.

Per material, every image its Principled BSDF reads (:func:`.materials.material_images`) through the uv
map being linted becomes a map of its role; its texels are Blender's (:func:`.images.held_textures`). An
image that reads another uv map, or whose uv cannot be followed, is left out with a note; so is one whose
texels cannot be read. Extend, Clip and Mirror are read exactly through texels laid out for the repeating sampler
(:mod:`.extension`); an interpolation other than Linear is read as Linear (the filter of design.md's visible
reading), with a note, and so is the extension of a UDIM image or of a rotated, unevenly laid-out map.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..loaders.texturemaps import TextureMap
from .extension import LAID_OUT, laid_out, margins
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


def object_textures(materials, uv_layer: str | None, render_uv_layer: str | None,
                    uv: np.ndarray | None = None) -> ObjectTextures:
    """The texture maps of ``materials`` (bpy.types.Material, None for an empty slot) read through the uv map
    ``uv_layer`` (None: the mesh has none, and nothing is read); ``render_uv_layer`` is the mesh's active
    render uv map, which an Image Texture with an unlinked Vector reads; ``uv`` (C, 2) float64 the mesh's uv
    on that map (how far outside [0, 1] an Extend or Clip image is read)."""
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
        where = f"{material}: image {use.image.name!r} ({use.role})"
        texture_map = TextureMap(role=use.role, path=key, name=use.image.name, source=f"Image Texture {use.node!r}",
                                 scale=use.scale, offset=use.offset, rotation=use.rotation)
        as_repeat = use.extension != "REPEAT"
        if use.extension in LAID_OUT and key in found.held and uv is not None:
            laid, note = _laid_out_map(found.held, texture_map, use.extension, uv)
            if note is not None:
                found.notes.append(f"{where}: {note}")
            if laid is not None:
                texture_map, as_repeat = laid, False
        ways = [f"extension {use.extension.title()}"] * as_repeat + \
               [f"interpolation {use.interpolation}"] * (use.interpolation != "Linear")
        if ways:
            found.notes.append(f"{where} has {' and '.join(ways)}: read as {'Repeat and ' * as_repeat}Linear")
        found.maps.setdefault(material, []).append(texture_map)
        found.grid_maps.setdefault(material, texture_map.path)  # the base colour's, listed first, else the first's
    return found


def _laid_out_map(held: dict, texture_map: TextureMap, extension: str,
                  uv: np.ndarray) -> tuple[TextureMap | None, str | None]:
    """``texture_map`` read through its image laid out for ``extension`` (:func:`.extension.laid_out`, added to
    ``held`` under a key of its own), and a note; None and why where the layout cannot be read through the
    map's transform (a rotation with a margin uneven in u and v)."""
    texture = held[texture_map.path]
    height, width = texture.texels.shape[:2]
    reached = texture_map.texture_uv(uv) if len(uv) else np.zeros((1, 2))
    margin, beyond = margins(reached.min(axis=0), reached.max(axis=0), (width, height))
    laid, layout = laid_out(texture, f"{texture_map.path}#{extension.lower()}", extension, margin)
    if texture_map.rotation and layout.scale[0] != layout.scale[1]:
        return None, "a rotated map of an Extend or Clip image"
    held[laid.path] = laid
    scale = tuple(s * a for s, a in zip(texture_map.scale, layout.scale))
    offset = tuple(o * a + b for o, a, b in zip(texture_map.offset, layout.scale, layout.offset))
    note = ("its uv reach more than one image outside [0, 1]: read as Repeat beyond" if beyond else None)
    return replace(texture_map, path=laid.path, scale=scale, offset=offset), note
