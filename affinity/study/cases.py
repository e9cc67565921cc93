"""The scenes of the study: the built-in figures (``affinity.scenes.study_scenes``) and mesh files.

A mesh file is framed whole by the renderer's default camera, z up where the
corpus manifest beside it (``MANIFEST.json``, as in ``../shared/meshes``) says so.
"""

from __future__ import annotations

import json
import os
from functools import partial
from pathlib import Path

from ..scenes import Scene, View


def mesh_cases(paths: list[str]) -> list[Scene]:
    """One scene per mesh file, framed whole; z up where the corpus manifest's notes say "z-up"."""
    from ..loaders import load

    return [Scene(os.path.basename(path), "mesh file", partial(load, path), View(up=_manifest_up_axis(path)))
            for path in paths]


def _manifest_up_axis(path: str) -> str | None:
    manifest = Path(path).parent / "MANIFEST.json"
    try:
        entries = json.loads(manifest.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    for entry in entries:
        if isinstance(entry, dict) and entry.get("file") == os.path.basename(path):
            return "z" if "z-up" in str(entry.get("notes", "")) else None
    return None
