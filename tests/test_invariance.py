"""Moving or scaling a mesh changes no flag (rounding-aware degeneracy, relative tolerances).

Offsets up to 1e9 and scales 1e-9 ... 1e9 of the shared meshes and the demo scenes
must flag the same faces for every rule; a face whose value lies within 1e-6
(relative) of its rule's threshold is exempt. Adding an offset rounds the input
coordinates themselves (by up to eps |offset| / 2, 6e-8 at 1e9), which changes a
face's true shape by that over its shortest edge: for offsets the exempt band
widens by 8 eps |offset| / shortest edge (relative). Measured: two faces of
gen_spot_cc4 (relative warp 0.0099986, Q202 threshold 0.01) read 0.0100012 at
offset 1e9, a change of 2.6e-4 that the rounded input really has.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from helpers.corpus import ABSENT, shared_mesh_paths

from affinity import scenes
from affinity.lint import lint_mesh
from affinity.settings import Settings

SHARED = shared_mesh_paths("*.obj")
DEMO_SCENES = [scenes.trapezoid, scenes.latlong_sphere, scenes.color_squares, scenes.quad_strip, scenes.demo_sphere,
               lambda: scenes.latlong_sphere(48, 24, dense_poles=True)]


def flags(mesh) -> dict[str, dict[int, float]]:
    """Rule code -> {face: value} of every finding."""
    return {h.code: dict(zip(h.faces.tolist(), h.values.tolist())) for h in lint_mesh(mesh, Settings())}


def near_threshold(code: str, value: float, band: float) -> bool:
    threshold = Settings().threshold(code)
    return threshold is not None and abs(value - threshold) <= band * max(abs(threshold), abs(value))


def input_rounding(mesh, offset: float) -> np.ndarray:
    """(F,) relative change of each face's shape that rounding the offset input causes."""
    corners = mesh.positions[mesh.corner_vertex]
    following = np.roll(np.arange(len(corners)), -1)
    starts = mesh.face_start[:-1]
    ends = mesh.face_start[1:] - 1
    following[ends] = starts
    edges = np.linalg.norm(corners[following] - corners, axis=1)
    shortest = np.minimum.reduceat(edges, starts) if len(starts) else np.zeros(0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return 8 * np.finfo(float).eps * abs(offset) / shortest


def assert_same_flags(original, moved, what, offset=0.0):
    before, after = flags(original), flags(moved)
    rounding = input_rounding(original, offset)
    for code in sorted(set(before) | set(after)):
        b, a = before.get(code, {}), after.get(code, {})
        changed = [f for f in set(b) ^ set(a)
                   if not near_threshold(code, b.get(f, a.get(f)), 1e-6 + (rounding[f] if f >= 0 else 0.0))]
        assert not changed, f"{what}: {code} flags changed on faces {sorted(changed)[:10]} ({len(changed)})"


OFFSET = np.array([1, -0.7, 0.4])


def moved_meshes(mesh):
    for offset in (1e3, 1e6, 1e9):
        yield f"offset {offset:g}", offset, dataclasses.replace(mesh, positions=mesh.positions + offset * OFFSET)
    for scale in (1e-9, 1e-3, 1e3, 1e9):
        yield f"scale {scale:g}", 0.0, dataclasses.replace(mesh, positions=mesh.positions * scale)


@pytest.mark.parametrize("make", DEMO_SCENES)
def test_demo_scenes_keep_their_flags_when_moved_or_scaled(make):
    mesh = make()
    for what, offset, moved in moved_meshes(mesh):
        assert_same_flags(mesh, moved, f"{mesh.path} {what}", offset)


@pytest.mark.skipif(not SHARED, reason=ABSENT)
@pytest.mark.parametrize("path", SHARED, ids=lambda p: p.name)
def test_shared_meshes_keep_their_flags_when_moved_or_scaled(path):
    from affinity.loaders import load

    mesh = load(str(path))
    for what, offset, moved in moved_meshes(mesh):
        assert_same_flags(mesh, moved, f"{path.name} {what}", offset)
