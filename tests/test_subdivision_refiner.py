"""affinity.subdivision.refine_uniform against OpenSubdiv: Far's uniform refinement (level points) of the small
shared meshes and three synthetic ones (creases and a corner, a hole, a uv seam through semi-sharp creases),
committed as fixtures by tests/oracle/make_fixtures.py, at levels 1-3 under every face-varying rule and, where
the mesh has a boundary, every boundary rule. Positions within 1e-6 of the bounding box, uv within 1e-6."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.osd_fixtures import FVAR_RULES, MESHES, load_fixture, refinements, scheme_options

from affinity.loaders import load
from affinity.subdivision import Scheme, refine_uniform

CASES = [(name, level, boundary) for name in MESHES for level, boundary in refinements(load_fixture(name))]


@pytest.fixture(scope="module")
def loaded():
    meshes = {}

    def mesh(name):
        if not MESHES[name].is_file():
            pytest.skip(f"{MESHES[name]} is absent")
        if name not in meshes:
            meshes[name] = load(str(MESHES[name]))
        return meshes[name]

    return mesh


@pytest.mark.parametrize(("name", "level", "boundary"), CASES, ids=[f"{n}-L{lv}-{b}" for n, lv, b in CASES])
def test_uniform_refinement_equals_far(loaded, name, level, boundary):
    mesh, arrays = loaded(name), load_fixture(name)
    key = f"L{level}_{boundary}"
    far_positions = arrays[f"{key}_positions"][arrays[f"{key}_faces"]]
    extent = np.ptp(mesh.positions, axis=0).max()
    for rule in FVAR_RULES:
        scheme = Scheme(boundary=boundary, fvar=rule, **scheme_options(arrays))
        refined = refine_uniform(mesh.face_start, mesh.corner_vertex, mesh.positions, level, scheme,
                                 {"uv": (mesh.texcoords, mesh.corner_texcoord)})
        assert np.array_equal(refined.base_face, arrays[f"{key}_base"]), rule
        assert np.array_equal(refined.hole, arrays[f"{key}_hole"]), rule
        positions = refined.positions[refined.corner_vertex].reshape(far_positions.shape)
        assert np.abs(positions - far_positions).max() <= 1e-6 * extent, rule
        values, corner_value = refined.channels["uv"]
        far_uv = arrays[f"{key}_{rule}_uv"][arrays[f"{key}_{rule}_uv_faces"]]
        assert np.abs(values[corner_value].reshape(far_uv.shape) - far_uv).max() <= 1e-6, rule


def test_the_fixtures_cover_every_rule_level_and_boundary_rule():
    """Every fixture holds levels 1-3 (the car: 1-3, the bilinear one: 1-2) under all six rules, and the three
    boundary rules where the mesh has a boundary."""
    for name in MESHES:
        arrays = load_fixture(name)
        done = refinements(arrays)
        levels = {level for level, _ in done}
        assert levels == ({1, 2} if name == "nonquads_bilinear" else {1, 2, 3}), name
        for level, boundary in done:
            assert all(f"L{level}_{boundary}_{rule}_uv" in arrays for rule in FVAR_RULES)
        assert {b for _, b in done} in ({"edgeAndCorner"}, {"none", "edgeOnly", "edgeAndCorner"}), name


def test_a_face_becomes_one_quad_per_corner_each_level():
    """A triangle, a quad and a pentagon: 3 + 4 + 5 quads at level 1, four times as many each level after."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0], [2.5, 0.5, 0],
                          [-1, 0.5, 0]], dtype=float)
    corners = np.array([0, 3, 7, 0, 1, 2, 3, 1, 4, 6, 5, 2])
    face_start = np.array([0, 3, 7, 12])
    for level, expected in ((1, 12), (2, 48), (3, 192)):
        refined = refine_uniform(face_start, corners, positions, level)
        assert refined.face_start[-1] == 4 * expected and len(refined.base_face) == expected
        assert np.array_equal(np.bincount(refined.base_face), [3, 4, 5] * np.array(4 ** (level - 1)))


def test_unknown_rules_and_loop_are_refused():
    with pytest.raises(ValueError, match="cornersPlus3"):
        Scheme(fvar="cornersPlus3")
    with pytest.raises(ValueError, match="Loop"):
        refine_uniform(np.array([0, 3]), np.array([0, 1, 2]), np.eye(3), 1, Scheme(scheme="loop"))
