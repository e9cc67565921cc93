"""Mesh -> renderer inputs: faces become quads without losing or inventing area."""

import numpy as np
import pytest

from affinity.draw.quads import render_corners
from affinity.draw.shading import shading_inputs
from affinity.mesh import Mesh, mesh_from_polygons
from affinity.scenes import color_squares, latlong_sphere


def mixed_mesh() -> Mesh:
    """A quad, a triangle and a regular hexagon, in that file order."""
    hexagon = [[np.cos(a), np.sin(a), 0.0] for a in np.linspace(0, 2 * np.pi, 7)[:-1]]
    positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]] + hexagon, dtype=float)
    sizes = [4, 3, 6]
    corners = [0, 1, 2, 3, 1, 4, 2, 5, 6, 7, 8, 9, 10]
    return Mesh("mixed", positions, np.cumsum([0] + sizes), np.array(corners), np.array([5, 6, 7]))


def polygon_area(points: np.ndarray) -> np.ndarray:
    x, y = points[..., 0], points[..., 1]
    return 0.5 * (x * np.roll(y, -1, -1) - np.roll(x, -1, -1) * y).sum(-1)


def test_triangles_repeat_a_corner_and_ngons_fan_with_the_same_area():
    mesh = mixed_mesh()
    faces, corners = render_corners(mesh)
    np.testing.assert_array_equal(faces, [0, 1, 2, 2, 2, 2])
    assert corners[1, 2] == corners[1, 3]
    areas = polygon_area(mesh.positions[mesh.corner_vertex[corners]])
    np.testing.assert_allclose(np.bincount(faces, weights=areas), [1.0, 0.5, 1.5 * np.sqrt(3) * 1.0])


def test_shading_inputs_pack_columns_by_mode():
    sphere = latlong_sphere(8, 4)
    _, corners = render_corners(sphere)
    shaded = shading_inputs(sphere, corners, "shaded")
    assert shaded.attrs.shape == (32, 4, 5) and shaded.uv == slice(0, 2) and shaded.normal == slice(2, 5)
    colours = shading_inputs(color_squares(), render_corners(color_squares())[1], "color")
    np.testing.assert_array_equal(colours.attrs[0, :, colours.color], [[0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 0, 0]])
    with pytest.raises(ValueError, match="no texture coordinates"):
        shading_inputs(color_squares(), corners[:2], "uv")
    flat = shading_inputs(mesh_from_polygons("q", np.eye(3)[[0, 1, 2, 2]] * [1, 1, 0], [[0, 1, 2, 3]]),
                          np.array([[0, 1, 2, 3]]), "normal")
    np.testing.assert_allclose(np.abs(flat.attrs[0, 0]), [0, 0, 1])
