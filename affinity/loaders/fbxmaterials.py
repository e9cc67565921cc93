"""The textures an FBX material reads through the mesh's uv, by role (design.md, "Textures by role").

A material's textures are its properties' connections (``DiffuseColor``,
``NormalMap``, ``Bump``, the PBR ``Maya|baseColor`` ...): :data:`ROLE_OF_PROPERTY`
names the role of each property a DCC tool writes, every other property is a
scalar map. A layered texture contributes each of its file textures. The file is
found as FBX stores it (:func:`texture_file`): the relative name against the
FBX file's folder, else the absolute name, else the image the file embeds, kept
in memory under :func:`embedded_name` and read from there
(:func:`affinity.loaders.imagesize.embed`).
"""

from __future__ import annotations

import os
import re
import struct

from .texturemaps import TextureMap

#: FBX material property -> role; other properties feed scalar maps.
ROLE_OF_PROPERTY = {
    "DiffuseColor": "base colour", "Diffuse": "base colour", "Maya|baseColor": "base colour",
    "Maya|TEX_color_map": "base colour", "3dsMax|Parameters|base_color_map": "base colour",
    "base_color": "base colour", "baseColor": "base colour",
    "NormalMap": "normal", "Maya|normalCamera": "normal", "Maya|TEX_normal_map": "normal",
    "3dsMax|Parameters|norm_map": "normal", "normal_map": "normal",
    "Bump": "height", "Maya|TEX_bump_map": "height", "3dsMax|Parameters|bump_map": "height",
}


#: A texture's or video's file name as a binary FBX node spells it (name length, name, ``S``, u32 length)
#: and as an ASCII one does.
_BINARY_FILE_NAME = re.compile(rb"(?:\x10RelativeFilename|\x08FileName)S(.{4})", re.S)
_ASCII_FILE_NAME = re.compile(rb'(?:RelativeFilename|FileName):\s*"([^"\n]*)"')


def named_texture_files(path: str, data: bytes) -> list[str]:
    """The image files the FBX file ``path`` with bytes ``data`` names (its textures' and videos' relative
    names resolved against its folder, and their absolute names), each once, read from the bytes without
    ufbx: what the result cache hashes beside the file."""
    names = []
    for match in _BINARY_FILE_NAME.finditer(data):
        (length,) = struct.unpack("<I", match.group(1))
        names.append(bytes(data[match.end():match.end() + length]))
    names += [match.group(1) for match in _ASCII_FILE_NAME.finditer(data)]
    folder = os.path.dirname(os.path.abspath(path))
    return list(dict.fromkeys(os.path.normpath(os.path.join(folder, os.fsdecode(name))) for name in names if name))


def embedded_name(fbx_path: str, name: str) -> str:
    """The name an image embedded in ``fbx_path`` is read by: ``/abs/file.fbx#textures/wood.png``."""
    return f"{os.path.abspath(fbx_path)}#{name}"


def texture_file(texture, fbx_path: str) -> tuple[str, str, bytes | None]:
    """Where a ufbx file texture's image is: ``(path, name as stored, embedded content or None)``.

    The relative name against the FBX file's folder when that file exists, else the absolute name when it
    exists, else the embedded content under :func:`embedded_name`, else the relative (or absolute) path
    resolved, missing, so the reading says so.
    """
    relative, absolute = texture.relative_filename, texture.absolute_filename
    name = relative or absolute
    candidates = []
    if relative:
        candidates.append(os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(fbx_path)), relative)))
    if absolute:
        candidates.append(os.path.normpath(absolute))
    for candidate in candidates:
        if os.path.isfile(candidate):
            return candidate, name, None
    content = bytes(texture.content) if texture.content else b""
    if content:
        return embedded_name(fbx_path, name or texture.name), name, content
    return (candidates[0] if candidates else ""), name, None


def material_maps(material, fbx_path: str, uv_name: str | None) -> tuple[list[TextureMap], dict[str, bytes]]:
    """The :class:`TextureMap` records of a ufbx material, and the embedded images they name (name ->
    content). A texture bound to another uv set than ``uv_name`` (when given) is left out."""
    maps, embedded = [], {}
    for bound in material.textures:
        texture = bound.texture
        files = list(texture.file_textures) or [texture]
        for file_texture in files:
            if uv_name is not None and file_texture.uv_set and file_texture.uv_set != uv_name:
                continue
            path, name, content = texture_file(file_texture, fbx_path)
            if not path:
                continue
            if content is not None:
                embedded[path] = content
            maps.append(TextureMap(role=ROLE_OF_PROPERTY.get(bound.material_prop, "scalar"), path=path,
                                   name=name, source=f"FBX {material.name}.{bound.material_prop}",
                                   **_placement(file_texture)))
    return maps, embedded


def _placement(texture) -> dict:
    """The texture's uv scale and offset (FBX ``Scaling``/``Translation`` of the texture), where it has them."""
    if not texture.has_uv_transform:
        return {}
    transform = texture.uv_transform
    return {"scale": (float(transform.scale.x), float(transform.scale.y)),
            "offset": (float(transform.translation.x), float(transform.translation.y))}
