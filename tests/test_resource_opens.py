"""One resource reader per run (issue 51): ``affinity check`` of a textured OBJ opens its MTL once and each texture
once, counted by an audit hook (``sys.addaudithook``, event ``open``: ``open()``, ``os.open`` and Pillow's opens
alike). On main the check opened Spot's MTL 3 times and its PNG 9 times."""

from __future__ import annotations

import collections
import os
import shutil
import sys

import pytest
from helpers.corpus import SHARED_MESHES
from helpers.sheared_grid import grid_obj

TEXTURED = SHARED_MESHES / "textured"

_counting: list[tuple[str, collections.Counter]] = []  # (folder, counts) while a count runs


def _count_opens(event: str, args: tuple) -> None:
    if event != "open" or not _counting or not isinstance(args[0], (str, bytes, os.PathLike)):
        return
    folder, counts = _counting[-1]
    path = os.path.abspath(os.fsdecode(args[0]))
    if os.path.dirname(path) == folder:
        counts[os.path.basename(path)] += 1


sys.addaudithook(_count_opens)  # hooks cannot be removed: this one counts only inside opens_during_check


def opens_during_check(mesh) -> collections.Counter:
    """Files of ``mesh``'s folder opened by ``affinity check --no-cache --format json MESH``, in process, by name."""
    from affinity.cli import main

    counts: collections.Counter = collections.Counter()
    _counting.append((os.path.dirname(os.path.abspath(mesh)), counts))
    try:
        code = main(["check", "--no-cache", "--format", "json", "-o", os.devnull, str(mesh)])
    finally:
        _counting.pop()
    assert code in (0, 1)
    return counts


def test_a_textured_grid_s_mtl_and_texture_are_opened_once(tmp_path):
    mesh = grid_obj(tmp_path)
    assert opens_during_check(mesh) == {"grid.obj": 1, "grid.mtl": 1, "checker.png": 1}


@pytest.mark.skipif(not TEXTURED.exists(), reason="../shared/meshes/textured is not in this checkout")
def test_spot_s_mtl_and_texture_are_opened_once(tmp_path):
    for name in ("spot_control_mesh_textured.obj", "spot.mtl", "spot_texture.png"):
        shutil.copy(TEXTURED / name, tmp_path / name)
    counts = opens_during_check(tmp_path / "spot_control_mesh_textured.obj")
    assert counts == {"spot_control_mesh_textured.obj": 1, "spot.mtl": 1, "spot_texture.png": 1}
