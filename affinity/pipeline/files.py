"""Which files a run checks: the paths given, directories expanded into their mesh files."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import UsageError

MESH_SUFFIXES = (".obj", ".ply", ".off", ".usd", ".usda", ".usdc", ".usdz")


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
                raise UsageError(f"{given}: no mesh files ({', '.join(MESH_SUFFIXES)}) in this directory")
            files.extend(found)
        elif os.path.exists(given):
            files.append(given)
        else:
            raise UsageError(f"{given}: no such file or directory")
    return list(dict.fromkeys(files))
