"""Wavefront material (.mtl) files: only what the linter needs, the texture maps per material.

Which statements name texture maps is the resource registry's
(:func:`affinity.loaders.resources.roles_named_in`): ``map_Kd`` today.
"""

from __future__ import annotations

import os

from .regular import SIDE_FILE_BUDGET, read_regular

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
    from .resources import roles_named_in

    try:
        text = read_regular(path, SIDE_FILE_BUDGET).decode("utf-8", "replace")
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
            name = texture_file_name(words[1:])
            maps.append((statements[words[0]], material, name,
                         os.path.normpath(os.path.join(folder, name.replace("\\", "/")))))
    return maps


def read_material_textures(path) -> dict[str, str]:
    """Material name -> ``map_Kd`` path (resolved against the .mtl's folder; the last statement
    of a material wins). A missing or unreadable file gives an empty dict."""
    return {material: texture for role, material, _, texture in material_maps(path) if role == "map_Kd"}


def texture_file_name(arguments: list[str]) -> str:
    """The file name of a ``map_Kd`` statement after its options.

    >>> texture_file_name(["-s", "1", "1", "1", "-clamp", "on", "wood grain.png"])
    'wood grain.png'
    """
    k = 0
    while k < len(arguments) - 1 and (arguments[k] in _FIXED_ARGUMENTS or arguments[k] in _VECTOR_OPTIONS):
        option = arguments[k]
        k += 1
        if option in _FIXED_ARGUMENTS:
            k += _FIXED_ARGUMENTS[option]
            continue
        for _ in range(3):
            if k < len(arguments) - 1 and _is_number(arguments[k]):
                k += 1
    return " ".join(arguments[k:])


def _is_number(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True
