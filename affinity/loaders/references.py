"""What a file names, one level down: the records of :mod:`.resources`, read by each format's reader.

An OBJ names material libraries (``mtllib``), a library names texture maps
(:mod:`.mtl`), a USD layer names layers and textures (:mod:`.usdlayers`), a
MaterialX document names images (:mod:`.usdmaterials`). The OBJ loader keeps
what a file references as ``Mesh.resources`` (:func:`obj_resources`); the
result cache hashes the files each file names (:func:`named_files`). The USD and
MaterialX readers are imported when such a file is read.
"""

from __future__ import annotations

import os

from .formats import format_named
from .mtl import material_maps
from .resources import Resource, mtllib_statements
from .texturemaps import tile_files


def obj_resources(path: str, data) -> list[Resource]:
    """What the OBJ file ``path`` with bytes ``data`` references: its material libraries and,
    for each readable one, the texture maps of every role named in MTL files; each file once
    (its first mention), libraries resolved against the OBJ's folder."""
    folder = os.path.dirname(os.fspath(path))
    resources, seen = [], set()
    for line, name in mtllib_statements(data):
        library = os.path.normpath(os.path.join(folder, name))
        if library in seen:
            continue
        seen.add(library)
        resources.append(Resource(role="mtllib", name=name, path=library, line=line))
        for role, material, texture_name, texture in material_maps(library):
            if (role, texture) not in seen:
                seen.add((role, texture))
                resources.append(Resource(role=role, name=texture_name, path=texture, line=line, library=name,
                                          material=material))
    return resources


def named_files(path: str, data=None) -> list[str]:
    """The files the file at ``path`` names itself (one level down, each once, in order):
    an OBJ's material libraries (from its bytes ``data``; read when None), an MTL file's
    texture maps of every role named in MTL files, a USD layer's sublayers, references and
    payloads and the files of its asset-valued attributes (textures; none without ``pxr``), a
    MaterialX document's image files, an FBX file's texture files. A UDIM texture names its tiles on
    disk. Other files name none. Paths are normalised, not made absolute."""
    suffix = os.path.splitext(path)[1].lower()
    if suffix == ".obj":
        if data is None:
            from .regular import read_regular

            data = read_regular(path)
        folder = os.path.dirname(path)
        return list(dict.fromkeys(os.path.normpath(os.path.join(folder, name))
                                  for _, name in mtllib_statements(data)))
    if suffix == ".mtl":
        return tile_files(texture for *_, texture in material_maps(path))
    if suffix in format_named("fbx").suffixes:
        from .fbxmaterials import named_texture_files
        from .regular import read_regular

        return named_texture_files(path, read_regular(path) if data is None else data)
    if suffix == ".mtlx":
        from .usdmaterials import mtlx_document_maps

        return tile_files(texture_map.path for texture_map in mtlx_document_maps(path, every=True))
    if suffix not in format_named("usd").suffixes:
        return []
    from .usdlayers import asset_paths, texture_asset_paths

    return [*asset_paths(path), *tile_files(texture_asset_paths(path))]
