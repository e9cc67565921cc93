"""The resource registry: what a mesh file references, by role, read by one reader per format.

A mesh file pulls in other files: an OBJ names material libraries (``mtllib``),
a library names texture maps by role (``map_Kd`` today), a USD layer names
sublayers, references and payloads. Each kind is one :class:`ResourceRole`
in :data:`ROLES`; the loaders list what a file references as
:class:`Resource` records (``Mesh.resources``), and the result cache's
dependency hash (:mod:`affinity.pipeline.cache`) and Q902 missing-resource
(:mod:`affinity.rules.file`) read the same roles, so a new texture role is one
:func:`register_role` call: the MTL reader then reads its statement, the cache
hashes its files (:mod:`.references`) and Q902 reports them missing. This
module imports none of the readers: they read it.
"""

from __future__ import annotations

import os
from dataclasses import dataclass


@dataclass(frozen=True, kw_only=True)
class ResourceRole:
    """One kind of file a mesh file references.

    Attributes
    ----------
    name : the role, ``"mtllib"``, ``"map_Kd"``, ``"usd-asset"``
    statement : the keyword that names such a file where it is named (``"map_Kd"`` in an MTL file)
    named_in : the kind of file whose statements name it: ``"obj"``, ``"mtl"`` or ``"usd"``
    image : the file must be a readable image (PNG, JPEG, BMP, TGA) to be of use
    summary : what the file is for, one line
    texture : for a texture map, what its texels are (design.md, "Textures by role"): ``"base colour"``,
        ``"normal"``, ``"height"`` or ``"scalar"``; None for other files
    """

    name: str
    statement: str
    named_in: str
    image: bool = False
    summary: str
    texture: str | None = None


@dataclass(frozen=True, kw_only=True)
class Resource:
    """One file a mesh references.

    Attributes
    ----------
    role : a key of :data:`ROLES`
    name : the file as the referencing statement spells it (``lib#1.mtl``, ``wood.png``)
    path : the file, resolved against the folder of the file that names it (normalised)
    line : 1-based line of the mesh file that pulls it in (a texture map: the line
        of its ``mtllib``); 0 where the format has no lines
    library : for a texture map, the ``mtllib`` name that names it; None otherwise
    material : for a texture map, the material it belongs to; None otherwise
    """

    role: str
    name: str
    path: str
    line: int = 0
    library: str | None = None
    material: str | None = None


#: Every resource role by name.
ROLES: dict[str, ResourceRole] = {}


def register_role(role: ResourceRole) -> ResourceRole:
    """Add ``role`` to :data:`ROLES`; a role is registered once."""
    if role.name in ROLES:
        raise ValueError(f"resource role {role.name} is registered already")
    if role.named_in not in ("obj", "mtl", "usd"):
        raise ValueError(f"resource role {role.name}: named_in {role.named_in!r} out of range")
    ROLES[role.name] = role
    return role


def unregister_role(name: str) -> None:
    """Remove a role registered at run time (tests, plug-ins)."""
    del ROLES[name]


register_role(ResourceRole(name="mtllib", statement="mtllib", named_in="obj",
                           summary="a Wavefront material library"))
register_role(ResourceRole(name="map_Kd", statement="map_Kd", named_in="mtl", image=True, texture="base colour",
                           summary="the diffuse colour texture of a material (the texel unit of the uv rule)"))
register_role(ResourceRole(name="norm", statement="norm", named_in="mtl", image=True, texture="normal",
                           summary="a tangent-space normal map"))
for _statement in ("bump", "map_Bump", "map_bump"):
    register_role(ResourceRole(name=_statement, statement=_statement, named_in="mtl", image=True, texture="height",
                               summary="a height map (a normal map when its image is one, as Blender writes them)"))
for _statement in ("map_Ks", "map_Ns", "map_Pr", "map_Pm", "map_Ke", "map_d", "disp"):
    register_role(ResourceRole(name=_statement, statement=_statement, named_in="mtl", image=True, texture="scalar",
                               summary="a scalar or secondary colour map of a material"))
register_role(ResourceRole(name="usd-asset", statement="sublayer, reference or payload", named_in="usd",
                           summary="a layer a USD stage composes"))


def roles_named_in(kind: str) -> list[ResourceRole]:
    """The roles whose files are named by statements of ``kind`` files (``"mtl"``), in registration order."""
    return [role for role in ROLES.values() if role.named_in == kind]


#: The statement's keyword, found by :func:`affinity.loaders.text.find_word` at its 'b'.
_MTLLIB = b"mtllib"


def uncommented(words: list[bytes]) -> list[bytes]:
    """A statement's words before the first one that starts a comment (``#``)."""
    comment = next((k for k, word in enumerate(words) if word.startswith(b"#")), len(words))
    return words[:comment]


def mtllib_statements(data) -> list[tuple[int, str]]:
    """``(line, name)`` of every ``mtllib`` statement of an OBJ file's bytes, in file order.

    The OBJ reading of a statement: a line whose first word is ``mtllib`` names the
    words after it up to a word that starts a comment (``lib#1.mtl`` is a name,
    ``lib #1`` is ``lib``), joined by single spaces, as the file system spells
    them. ``data`` is bytes-like; a line is 1-based; a '\\' line continuation is not
    followed (a library name never spans lines).
    """
    from .text import find_word

    found, last_line = [], -1
    counted, line = 0, 1  # lines are counted from the previous statement on, not from the start each time
    start = find_word(data, _MTLLIB, len(_MTLLIB) - 1)
    while start >= 0:
        end = data.find(b"\n", start)
        end = len(data) if end < 0 else end
        line_start = data.rfind(b"\n", 0, start) + 1
        words = uncommented(bytes(data[line_start:end]).split())
        start = find_word(data, _MTLLIB, len(_MTLLIB) - 1, end)
        if line_start == last_line or words[:1] != [b"mtllib"]:  # said again on its line, or another statement
            continue
        last_line = line_start
        line += data.count(b"\n", counted, line_start)
        counted = line_start
        if len(words) > 1:
            found.append((line, os.fsdecode(b" ".join(words[1:]))))
    return found
