"""The real meshes of ``../shared/meshes``: the one place their path is spelled.

Tests take the ``shared_meshes`` fixture (``tests/conftest.py``: the folder, skipping
without it), a ``manifest_entry`` argument (parametrized over MANIFEST.json), or,
to parametrize over the files at collection time, :func:`shared_mesh_paths`.
"""

from __future__ import annotations

import json
from pathlib import Path

SHARED_MESHES = Path(__file__).resolve().parents[3] / "shared" / "meshes"
MANIFEST = SHARED_MESHES / "MANIFEST.json"
ABSENT = f"{SHARED_MESHES} is absent: the tests on real meshes were skipped"


def manifest_entries() -> list[dict]:
    """MANIFEST.json's entries (file, counts, licence, ...); empty without the folder."""
    return json.loads(MANIFEST.read_text(encoding="utf-8")) if MANIFEST.is_file() else []


def shared_mesh_paths(pattern: str = "*.obj") -> list[Path]:
    """The shared meshes matching ``pattern``, sorted; empty without the folder (for parametrizing at
    collection time: pair it with a skip when it is empty)."""
    return sorted(SHARED_MESHES.glob(pattern)) if SHARED_MESHES.is_dir() else []
