"""``affinity check``: find the mesh files, lint each one, collect one report per file.

Each file is checked independently; an unreadable file becomes a report with an
``error`` and never stops the others.
"""

from __future__ import annotations

import os
from pathlib import Path

from .findings import FileReport
from .mesh import MeshError, SkippedFile
from .settings import Settings

MESH_SUFFIXES = (".obj", ".ply", ".off")


class UsageError(Exception):
    """Bad command-line input that is not about one mesh file (exit 2)."""


def collect_paths(paths: list[str]) -> list[str]:
    """Expand directories (recursively, sorted) into their mesh files.

    Files named explicitly are kept whatever their extension, so the loader can
    say what is wrong with them. A directory with no mesh file in it, or a path
    that does not exist, is a :class:`UsageError`.
    """
    files: list[str] = []
    for given in paths:
        if os.path.isdir(given):
            found = sorted(
                str(p) for p in Path(given).rglob("*")
                if p.suffix.lower() in MESH_SUFFIXES and p.is_file()
            )
            if not found:
                raise UsageError(f"{given}: no .obj, .ply or .off files in this directory")
            files.extend(found)
        elif os.path.exists(given):
            files.append(given)
        else:
            raise UsageError(f"{given}: no such file or directory")
    return list(dict.fromkeys(files))


def check_file(path: str, settings: Settings) -> FileReport:
    """Load and lint one file; never raises for bad input."""
    from .lint import lint_mesh
    from .loaders import load

    try:
        mesh = load(path)
    except SkippedFile as skip:
        return FileReport(path, skipped=skip.reason)
    except MeshError as err:
        return FileReport(path, error=err.reason, error_line=err.line)
    return FileReport(
        path,
        counts=mesh.counts(),
        hits=lint_mesh(mesh, settings),
        group_names=list(mesh.group_names),
    )


def check_paths(files: list[str], settings: Settings) -> list[FileReport]:
    """Check every file in order."""
    return [check_file(path, settings) for path in files]
