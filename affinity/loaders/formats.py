"""The format table: one :class:`MeshFormat` record per mesh file format the loaders read.

Everything that depends on which formats exist reads :data:`LOADERS`: the
loader dispatch (:func:`affinity.loaders.load`), the directory walk
(:data:`affinity.pipeline.files.MESH_SUFFIXES`), the result cache (which formats
are USD), the command-line help and the pre-commit hook's ``files:`` pattern
(a test compares ``.pre-commit-hooks.yaml`` with :func:`hook_pattern`). Adding a
format is one record here and its loader module. Imports nothing: the loaders
are imported when a file of their format is read.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True, kw_only=True)
class MeshFormat:
    """One mesh file format.

    Attributes
    ----------
    key : short name (``"obj"``, ``"usd"``)
    title : what it is called (``"Wavefront OBJ"``)
    suffixes : file name endings, lower case with the dot (``(".obj",)``)
    loader : ``"module:function"`` of its reader, the module relative to :mod:`affinity.loaders`;
        the function takes the path (and ``source=`` when ``whole_source``)
    whole_source : the reader parses the file's bytes as a caller read them
        (``source=``), so a check reads such a file once
    extra : the pip extra its reader needs (``"usd"``: usd-core), or None
    scene : the reader takes the scene options (:class:`~affinity.loaders.usd.UsdOptions`: time, uv set)
        after the path, and locates faces by node or prim path (``path:/A/B:face N``)
    """

    key: str
    title: str
    suffixes: tuple[str, ...]
    loader: str
    whole_source: bool = False
    extra: str | None = None
    scene: bool = False

    def load_function(self) -> Callable:
        """The reader function, imported now."""
        module, _, function = self.loader.partition(":")
        return getattr(importlib.import_module(module, __package__), function)


#: Every format, in the order help texts list them.
FORMATS: tuple[MeshFormat, ...] = (
    MeshFormat(key="obj", title="Wavefront OBJ", suffixes=(".obj",), loader=".obj:load_obj", whole_source=True),
    MeshFormat(key="ply", title="PLY", suffixes=(".ply",), loader=".ply:load_ply"),
    MeshFormat(key="off", title="OFF", suffixes=(".off",), loader=".off:load_off"),
    MeshFormat(key="usd", title="USD", suffixes=(".usd", ".usda", ".usdc", ".usdz"), loader=".usd:load_usd",
               extra="usd", scene=True),
    MeshFormat(key="fbx", title="FBX", suffixes=(".fbx",), loader=".fbx:load_fbx", extra="fbx", scene=True),
)

#: File suffix -> its format: the one format table.
LOADERS: dict[str, MeshFormat] = {suffix: f for f in FORMATS for suffix in f.suffixes}

#: Every suffix a mesh file may have, in table order.
MESH_SUFFIXES: tuple[str, ...] = tuple(LOADERS)


def format_named(key: str) -> MeshFormat:
    """The format with ``key`` (``"usd"``)."""
    return next(f for f in FORMATS if f.key == key)


def described() -> str:
    """The formats for a help text, each extra named.

    >>> described()
    '.obj/.ply/.off and USD (.usd/.usda/.usdc/.usdz, with the usd extra) and FBX (.fbx, with the fbx extra)'
    """
    text = "/".join(suffix for f in FORMATS if f.extra is None for suffix in f.suffixes)
    for f in FORMATS:
        if f.extra is not None:
            text += f" and {f.title} ({'/'.join(f.suffixes)}, with the {f.extra} extra)"
    return text


def hook_pattern() -> str:
    """The pre-commit hook's ``files:`` regular expression: every suffix, case-insensitive."""
    return r"(?i)\.(" + "|".join(suffix.lstrip(".") for suffix in MESH_SUFFIXES) + ")$"
