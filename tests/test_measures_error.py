"""The ``error`` reading against the sampled supremum of split minus bilinear (tests/split_reference.py)."""


import numpy as np
import pytest
from helpers.split_reference import (
    random_convex_quad,
    random_plane_frame,
    sampled_sup,
    split_minus_bilinear,
)

from affinity.geometry import planar_quads
from affinity.measures import split_error


def error_of(corners, values, diagonal="02", measure="error"):
    values = np.asarray(values, float).reshape(4, -1)
    return float(np.linalg.norm(split_error(planar_quads(np.asarray(corners, float)[None]), values[None], diagonal,
                                            measure)[0]))


def in_random_plane(rng, xy):
    """(4, 2) in-plane corners -> (4, 3) corners in a random plane of 3-D, offset at random."""
    return np.column_stack([xy, np.zeros(4)]) @ random_plane_frame(rng) + rng.normal(size=3) * 3


@pytest.mark.slow  # dense sampling of random quads
def test_equals_the_sampled_supremum_on_random_convex_planar_quads():
    rng = np.random.default_rng(11)
    for _ in range(25):
        corners = in_random_plane(rng, random_convex_quad(rng))
        uv = rng.normal(size=(4, 2))
        for diagonal in ("02", "13", "both"):
            assert error_of(corners, uv, diagonal) == pytest.approx(sampled_sup(corners, uv, diagonal), rel=0.01)
        lengths = np.linalg.norm(corners[2] - corners[0]), np.linalg.norm(corners[3] - corners[1])
        shortest = "02" if lengths[0] <= lengths[1] else "13"
        assert error_of(corners, uv, "shortest") == pytest.approx(sampled_sup(corners, uv, shortest), rel=0.01)


@pytest.mark.parametrize("ratio", [0.5, 0.1, 1e-2, 1e-4, 1e-6, 1e-9])
@pytest.mark.parametrize("diagonal", ["02", "13", "both"])
def test_equals_the_sampled_supremum_on_trapezoids_down_to_near_triangles(ratio, diagonal):
    rng = np.random.default_rng(3)
    xy = np.array([[-1, 0], [1, 0], [ratio, 1.5], [-ratio, 1.5]])
    corners = in_random_plane(rng, xy)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    value = error_of(corners, uv, diagonal)
    assert value == pytest.approx(sampled_sup(corners, uv, diagonal), rel=0.01)
    assert value <= np.sqrt(2) * (1 + 1e-12)  # the corner extent of the unit square


def test_an_exact_pole_quad_reads_the_whole_width_of_its_uv():
    rng = np.random.default_rng(5)
    corners = in_random_plane(rng, np.array([[0, 0], [0, 0], [1, 1], [-1, 1.2]]))
    uv = np.array([[0.25, 1.0], [0.3125, 1.0], [0.3125, 0.875], [0.25, 0.875]])
    for diagonal in ("02", "13", "both"):
        value = error_of(corners, uv, diagonal)
        assert value == pytest.approx(sampled_sup(corners, uv, diagonal), rel=0.01)
    assert error_of(corners, uv, "02") == pytest.approx(0.0625)  # |uv_0 - uv_1|


def test_on_parallelograms_equals_the_shift_at_the_centre():
    """Today's value there: |a0 - a1 + a2 - a3| / 4 (bilinear centre minus either split's)."""
    rng = np.random.default_rng(8)
    for _ in range(10):
        u, v = rng.normal(size=(2, 2))
        corners = in_random_plane(rng, np.array([[0, 0], u, u + v, v]))
        values = rng.normal(size=(4, 3))
        shift = np.linalg.norm(values[0] - values[1] + values[2] - values[3]) / 4
        for diagonal in ("02", "13", "both", "shortest"):
            assert error_of(corners, values, diagonal) == pytest.approx(shift, rel=1e-9)
            assert error_of(corners, values, diagonal, "centre") == pytest.approx(shift, rel=1e-9)
        assert shift == pytest.approx(sampled_sup(corners, values, "02"), rel=0.01)


def test_centre_reading_is_the_sampled_difference_at_the_corner_mean():
    rng = np.random.default_rng(9)
    for _ in range(10):
        corners = in_random_plane(rng, random_convex_quad(rng))
        values = rng.normal(size=(4, 2))
        for diagonal in ("02", "13"):
            at_centre = split_minus_bilinear(corners, values, diagonal, np.array([0.5]), np.array([0.5]))[0]
            assert error_of(corners, values, diagonal, "centre") == pytest.approx(at_centre, rel=1e-9)


def corner_extent(values):
    """(Q, 4, K) -> (Q,) largest distance between two corner values."""
    return np.linalg.norm(values[:, :, None] - values[:, None, :], axis=-1).max(axis=(1, 2))


def test_never_above_the_corner_extent_on_random_convex_and_folded_quads():
    rng = np.random.default_rng(12)
    convex = np.stack([in_random_plane(rng, random_convex_quad(rng)) for _ in range(300)])
    folded = rng.normal(size=(300, 4, 3))  # concave, bow-tie and nonplanar quads among them
    for corners in (convex, folded):
        values = rng.normal(size=(len(corners), 4, 2))
        quads = planar_quads(corners)
        for diagonal in ("02", "13", "both", "shortest"):
            error = np.linalg.norm(split_error(quads, values, diagonal), axis=1)
            assert (error <= corner_extent(values) * (1 + 1e-12)).all()
            assert np.isfinite(error).all()


def test_never_above_the_corner_extent_on_the_shared_meshes(shared_meshes):
    """Every Q101-Q103 value of every quad (linted at threshold -inf) against the largest
    distance between two of its corner values, in the rule's unit."""
    from affinity.lint import lint_mesh, quad_texel_grid
    from affinity.loaders import load
    from affinity.settings import Settings

    checked = 0
    for path in sorted(shared_meshes.glob("*.obj")):
        mesh = load(str(path))
        faces, corners = mesh.faces_of_size(4)
        grid = quad_texel_grid(mesh, Settings())  # each quad in its own texture's texels, as the lint counts them
        units = {"Q101": ("texcoords", None), "Q102": ("colors", 255.0), "Q103": ("normals", None)}
        for diagonal in ("both", "shortest"):
            settings = Settings(diagonal=diagonal, thresholds={code: -np.inf for code in units})
            for hits in lint_mesh(mesh, settings):
                if hits.code not in units:
                    continue
                name, scale = units[hits.code]
                if hits.code == "Q101":
                    scale = np.broadcast_to(grid.of(hits.faces), (len(hits.faces), 2))[:, None, :]
                values = mesh.corner_attribute(name, corners[np.searchsorted(faces, hits.faces)])
                if hits.code == "Q103":  # degrees: the extent of unit normals turns the mean normal
                    unit = values / np.linalg.norm(values, axis=2, keepdims=True)
                    mean = np.linalg.norm(unit.mean(axis=1), axis=1)
                    extent = np.degrees(np.arctan2(corner_extent(unit), mean))
                else:
                    extent = corner_extent(values * scale)
                assert (hits.values <= extent * (1 + 1e-9) + 1e-12).all(), (path.name, hits.code)
                checked += len(hits.values)
    assert checked > 50000
