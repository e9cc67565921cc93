"""Wavefront material (.mtl) files: only what the linter needs, the texture maps per material.

Which statements name texture maps is the resource registry's
(:func:`affinity.loaders.resources.roles_named_in`): ``map_Kd``, ``norm``, ``bump`` and the scalar maps.
"""

from __future__ import annotations

import itertools
import os

from .regular import SIDE_FILE_BUDGET
from .resources import ROLES, roles_named_in
from .sidefiles import read_side_file
from .texturemaps import TextureMap

#: ``map_Kd`` options with a fixed number of arguments.
_FIXED_ARGUMENTS = {
    "-blendu": 1, "-blendv": 1, "-bm": 1, "-boost": 1, "-cc": 1, "-clamp": 1,
    "-imfchan": 1, "-mm": 2, "-texres": 1, "-type": 1,
}  # fmt: skip
#: ``map_Kd`` options followed by one to three numbers.
_VECTOR_OPTIONS = ("-o", "-s", "-t")


def material_maps(path) -> list[tuple[str, str, str, str]]:
    """``(role, material, name, path)`` of every texture map statement of the MTL file ``path``,
    in file order: the resource role (``"map_Kd"``), the material, the file name as written
    after the statement's options, and that file resolved against the .mtl's folder.

    A missing or unreadable file gives an empty list: materials are optional.
    """
    return [(role, material, texture.name, texture.path) for role, material, texture in map_statements(path)]


def map_statements(path) -> list[tuple[str, str, TextureMap]]:
    """``(resource role, material, texture)`` of every texture map statement of the MTL file ``path``
    (the roles the resource registry names in MTL files), in file order: the texture as a
    :class:`~affinity.loaders.texturemaps.TextureMap` whose role is the resource role's kind of texels
    (None for a role that names none), its file resolved against the .mtl's folder, and the statement's
    ``-s`` scale and ``-o`` offset of u and v (w is not used by a 2-D texture). A missing or unreadable
    file gives an empty list."""
    try:
        text = read_side_file(path, SIDE_FILE_BUDGET).decode("utf-8", "replace")
    except OSError:
        return []
    statements = {role.statement: role.name for role in roles_named_in("mtl")}
    folder = os.path.dirname(os.fspath(path))
    maps = []
    material = None
    for line in text.splitlines():
        words = line.split()
        words = words[: next((k for k, w in enumerate(words) if w.startswith("#")), len(words))]
        if len(words) < 2:
            continue
        if words[0] == "newmtl":
            material = " ".join(words[1:])
        elif words[0] in statements and material is not None:
            name, options = map_arguments(words[1:])
            scale, offset = options.get("-s", (1.0, 1.0)), options.get("-o", (0.0, 0.0))
            role = statements[words[0]]
            maps.append((role, material, TextureMap(
                role=ROLES[role].texture, name=name, source=words[0],
                path=os.path.normpath(os.path.join(folder, name.replace("\\", "/"))),
                scale=(scale[0], scale[1] if len(scale) > 1 else 1.0),
                offset=(offset[0], offset[1] if len(offset) > 1 else 0.0),
                wrap=("clamp", "clamp") if clamped(words[1:]) else ("repeat", "repeat"))))
    return maps


def clamped(arguments: list[str]) -> bool:
    """Whether a texture map statement's options say ``-clamp on`` (the texture is not repeated).

    >>> clamped(["-clamp", "on", "wood.png"]), clamped(["-clamp", "off", "wood.png"])
    (True, False)
    """
    return any(a == "-clamp" and b.lower() == "on" for a, b in itertools.pairwise(arguments))


def texture_file_name(arguments: list[str]) -> str:
    """The file name of a ``map_Kd`` statement after its options.

    >>> texture_file_name(["-s", "1", "1", "1", "-clamp", "on", "wood grain.png"])
    'wood grain.png'
    """
    return map_arguments(arguments)[0]


def map_arguments(arguments: list[str]) -> tuple[str, dict[str, tuple[float, ...]]]:
    """The file name of a texture map statement after its options, and its vector options
    (``-o``, ``-s``, ``-t``) with the numbers given (one to three).

    >>> map_arguments(["-s", "2", "2", "1", "-o", "0.5", "-clamp", "on", "wood grain.png"])
    ('wood grain.png', {'-s': (2.0, 2.0, 1.0), '-o': (0.5,)})
    """
    k, vectors = 0, {}
    while k < len(arguments) - 1 and (arguments[k] in _FIXED_ARGUMENTS or arguments[k] in _VECTOR_OPTIONS):
        option = arguments[k]
        k += 1
        if option in _FIXED_ARGUMENTS:
            k += _FIXED_ARGUMENTS[option]
            continue
        numbers = []
        while len(numbers) < 3 and k < len(arguments) - 1 and _is_number(arguments[k]):
            numbers.append(float(arguments[k]))
            k += 1
        vectors[option] = tuple(numbers)
    return " ".join(arguments[k:]), vectors


def _is_number(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def obj_material_maps(resources: list) -> dict[str, list[TextureMap]]:
    """Material -> its texture maps, from an OBJ's ``mtllib`` resources (``Mesh.resources``): the first
    library defining a material wins, within a library its last statement of each role (as a renderer
    reads them)."""
    maps: dict[str, list[TextureMap]] = {}
    for library in (r for r in resources if r.role == "mtllib"):
        own: dict[str, dict[str, TextureMap]] = {}
        for role, material, texture in map_statements(library.path):
            if texture.role is not None:
                own.setdefault(material, {})[role] = texture
        for material, by_statement in own.items():
            maps.setdefault(material, list(by_statement.values()))
    return maps
