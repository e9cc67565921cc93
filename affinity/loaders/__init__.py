"""Mesh loaders: ``load(path) -> Mesh`` dispatching on the file extension.

Supported (the format table, :data:`.formats.LOADERS`): Wavefront OBJ (``.obj``),
PLY (``.ply``; ASCII and binary) and OFF (``.off``; with the C/N/ST prefixes), and
USD stages (``.usd``, ``.usda``, ``.usdc``, ``.usdz``) when usd-core is installed
(see :mod:`affinity.loaders.usd`), and FBX (``.fbx``) when ufbx is installed
(:mod:`affinity.loaders.fbx`). Every problem with the input is a
:class:`~affinity.mesh.MeshError` naming the file and line; a Git LFS pointer
is a :class:`~affinity.mesh.SkippedFile`. A reader is imported when a file of its
format is read (NumPy; ``pxr`` for USD).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from ..errors import MeshError, SkippedFile
from .formats import LOADERS
from .regular import RefusedFile, open_regular

if TYPE_CHECKING:
    from ..mesh import Mesh
    from .usd import UsdOptions

LFS_POINTER = b"version https://git-lfs.github.com/spec/"


def _opened(path, read):
    """``read(fh)`` of the file at ``path`` opened for bytes; MeshError for a directory, a FIFO,
    a device or an unreadable file (:func:`.regular.open_regular`), before any byte is read."""
    try:
        with open_regular(path) as fh:
            return read(fh)
    except RefusedFile as error:
        raise MeshError(path, 0, error.strerror) from None
    except OSError as error:
        raise MeshError(path, 0, f"cannot read: {error.strerror or error}") from None


def read_source(path) -> bytes:
    """Every byte of the file at ``path``, read once for all who need them (the OBJ reader, the
    cache's hash, the inline-ignore scan). MeshError for a directory or an unreadable file."""
    return _opened(path, lambda fh: fh.read())


def reads_whole(path) -> bool:
    """Whether the loader of ``path`` parses the file's bytes as :func:`read_source` gives them (OBJ)."""
    found = LOADERS.get(os.path.splitext(os.fspath(path))[1].lower())
    return found is not None and found.whole_source


def load(path, usd: UsdOptions | None = None, source: bytes | None = None) -> Mesh:
    """Read the mesh at ``path``, choosing the reader by its extension (case-insensitive).

    ``usd`` says how to read a USD stage (time, uv primvar) or an FBX scene (uv set); other formats ignore it.
    ``source`` is the file's bytes (:func:`read_source`) when the caller has them: an
    OBJ file is then not opened again; other formats open the file themselves.

    Raises
    ------
    MeshError
        Unknown extension, missing/unreadable file, directory, empty file or any
        content that is not a valid mesh (with the 1-based line where there is one).
    SkippedFile
        The file is a Git LFS pointer, not the mesh itself.
    """
    extension = os.path.splitext(os.fspath(path))[1].lower()
    if extension not in LOADERS:
        known = ", ".join(LOADERS)
        raise MeshError(path, 0, f"unknown mesh format {extension or '(no extension)'!r}; expected one of {known}")
    mesh_format = LOADERS[extension]
    if source is None and mesh_format.whole_source:
        source = read_source(path)
    if source is not None:
        head = source[: len(LFS_POINTER)]
    else:
        head = _opened(path, lambda fh: fh.read(len(LFS_POINTER)))
    if not head:
        raise MeshError(path, 0, "empty file")
    if head == LFS_POINTER:
        raise SkippedFile(path, "lfs-pointer")
    try:
        read = mesh_format.load_function()
        if mesh_format.scene:
            return read(path, usd)
        if mesh_format.whole_source:
            return read(path, source=source)
        return read(path)
    except OSError as error:  # e.g. the file vanished or became unreadable while reading
        raise MeshError(path, 0, f"cannot read: {error.strerror or error}") from None


__all__ = ["LOADERS", "load", "read_source", "reads_whole"]
