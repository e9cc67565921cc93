"""The affinity test (Bloomenthal 2022, Listing 3) against closed forms and invariances."""

import numpy as np
import pytest

from affinity.geometry import planar_quads
from affinity.measures import (
    barycentric_score,
    color_steps,
    corner_barycentrics,
    normal_degrees,
    selected_corners,
    split_error,
    texels,
)


def misplacement(quads, attrs, diagonal="both"):
    """The ``centre`` reading: the split's shift at the corner mean."""
    return split_error(quads, attrs, diagonal, "centre")

UNIT_SQUARE_UV = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
DIAGONALS = ["both", "02", "13", "shortest"]


def random_rotation(rng, dimension=3):
    q, r = np.linalg.qr(rng.normal(size=(dimension, dimension)))
    q *= np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def scores(corners, uv, diagonal="both"):
    """(|centre shift|, barycentric score) of quads (Q, 4, 3) with uv (Q, 4, 2)."""
    quads = planar_quads(corners)
    m = np.linalg.norm(misplacement(quads, uv, diagonal), axis=1)
    return m, barycentric_score(quads, planar_quads(uv), diagonal)


def trapezoid(ratio, width=2.0, height=1.0):
    """(1, 4, 3) isosceles trapezoid in the x-y plane: bottom corners 0, 1 of width
    ``width``, top corners 2, 3 of width ``ratio * width``, counter-clockwise."""
    w1, w2 = width / 2, ratio * width / 2
    return np.array([[[-w1, 0, 0], [w1, 0, 0], [w2, height, 0], [-w2, height, 0]]])


def test_corner_barycentrics_match_a_direct_solve():
    rng = np.random.default_rng(0)
    corners = rng.normal(size=(50, 4, 3))
    quads = planar_quads(corners)
    b = corner_barycentrics(quads)
    for q in range(len(corners)):
        for i in range(4):
            others = quads.xy[q, [(i + 1) % 4, (i + 2) % 4, (i + 3) % 4]]
            system = np.vstack([others.T, np.ones(3)])  # sum_j b_j (x_j, y_j, 1) = (x_i, y_i, 1)
            expected = np.linalg.solve(system, np.append(quads.xy[q, i], 1))
            np.testing.assert_allclose(b[q, i], expected, rtol=1e-8, atol=1e-8)


def test_degenerate_reference_triangles_are_marked_not_guessed():
    pole = trapezoid(0.0)  # corners 2 and 3 coincide
    b = corner_barycentrics(planar_quads(pole))
    assert np.isnan(b[0, :2]).all()  # triangles (1, 2, 3) and (2, 3, 0) have no area
    np.testing.assert_allclose(b[0, 3], [0, 0, 1])  # corner 3 is corner 2


def test_affine_parallelogram_scores_zero_under_any_similarity_of_either_space():
    rng = np.random.default_rng(1)
    for _ in range(50):
        u, v = rng.normal(size=(2, 2))
        plane = np.array([[0, 0], u, u + v, v])  # parallelogram in its plane
        texture_map = rng.normal(size=(2, 2))  # any non-degenerate affine uv
        uv = plane @ texture_map.T + rng.normal(size=2)
        # a random similarity of the uv space, and one of the positions
        uv = (uv @ random_rotation(rng, 2).T) * 10 ** rng.uniform(-3, 3) + rng.normal(size=2) * 100
        corners = np.column_stack([plane, np.zeros(4)]) @ random_rotation(rng).T
        corners = corners * 10 ** rng.uniform(-3, 3) + rng.normal(size=3) * 100
        uv_span = np.ptp(uv, axis=0).max()
        for diagonal in DIAGONALS:
            m, score = scores(corners[None], uv[None], diagonal)
            assert m[0] < 1e-9 * uv_span and score[0] < 1e-7


def test_trapezoid_with_unit_square_uv_in_closed_form():
    """Isosceles trapezoid, bottom width w1 (corners 0, 1), top w2 = r w1 (2, 3), height h,
    unit-square uv. Corner 0 against triangle (1, 2, 3): the affine u of that triangle is
    u = (x + w2/2)/w2 + c (y - h) with u(p1) = 1, so c h = (w1 - w2)/(2 w2), and at p0
    u = -(1 - r)/r instead of 0; v = y/h fits exactly: the residual is (1 - r)/r.
    Barycentrics of p0: (1, -1/r, 1/r) against (1, -1, 1) in uv: distance sqrt(2)(1 - r)/r.
    The centre lies in the larger triangle (against the long base), whose corner
    residual is 1 - r: the centre shift is (1 - r)/4 on either diagonal. Neither depends on
    the size of the quad (tolerances are relative, not an absolute epsilon)."""
    for r in [0.25, 0.5, 0.75]:
        for size in [1e-6, 1.0, 1e6]:
            m, score = scores(trapezoid(r, width=3.0, height=0.7) * size, UNIT_SQUARE_UV[None])
            np.testing.assert_allclose(m, [(1 - r) / 4])
            np.testing.assert_allclose(score, [np.sqrt(2) * (1 - r) / r])
        assert texels(misplacement(planar_quads(trapezoid(r)), UNIT_SQUARE_UV[None]), 1024)[0] > 0.5


def test_parallelogram_with_bilinear_uv_field_moves_the_centre_by_the_split_error():
    """On a parallelogram the bilinear uv at the centre is the corner mean; the split
    along 0-2 gives the midpoint of diagonal 0-2 there (the centre lies on it), along
    1-3 the midpoint of 1-3. The centre reading is split minus bilinear."""
    rng = np.random.default_rng(2)
    for _ in range(20):
        u, v = rng.normal(size=(2, 3))
        corners = np.array([np.zeros(3), u, u + v, v]) + rng.normal(size=3)
        uv = rng.normal(size=(4, 2))  # any corners: a bilinear field, not affine
        bilinear = uv.mean(axis=0)
        split_02, split_13 = (uv[0] + uv[2]) / 2, (uv[1] + uv[3]) / 2
        quads = planar_quads(corners[None])
        np.testing.assert_allclose(misplacement(quads, uv[None], "02")[0], split_02 - bilinear, atol=1e-12)
        np.testing.assert_allclose(misplacement(quads, uv[None], "13")[0], split_13 - bilinear, atol=1e-12)
        for diagonal in ("both", "shortest"):
            np.testing.assert_allclose(
                np.linalg.norm(misplacement(quads, uv[None], diagonal)),
                np.linalg.norm(bilinear - split_02),
                rtol=1e-9,
            )


def lat_long_sphere(n_lon, n_lat):
    """Quads (n_lat, n_lon, 4, 3) and uv of a unit lat-long sphere, rows from the south
    pole up, counter-clockwise seen from outside. The pole rows repeat the pole corner."""
    lon = np.linspace(0, 2 * np.pi, n_lon + 1)
    lat = np.linspace(-np.pi / 2, np.pi / 2, n_lat + 1)
    lat_grid, lon_grid = np.meshgrid(lat, lon, indexing="ij")
    points = np.stack(
        [np.cos(lat_grid) * np.cos(lon_grid), np.cos(lat_grid) * np.sin(lon_grid), np.sin(lat_grid)], axis=-1
    )
    points[0], points[-1] = [0, 0, -1], [0, 0, 1]  # the pole exactly, repeated
    v_grid, u_grid = np.meshgrid(np.linspace(0, 1, n_lat + 1), np.linspace(0, 1, n_lon + 1), indexing="ij")
    uv = np.stack([u_grid, v_grid], axis=-1)

    def quads(grid):
        return np.stack([grid[:-1, :-1], grid[:-1, 1:], grid[1:, 1:], grid[1:, :-1]], axis=2)

    return quads(points), quads(uv)


@pytest.mark.parametrize("n_lon, n_lat", [(16, 8), (64, 32)])
@pytest.mark.parametrize("diagonal", DIAGONALS)
def test_lat_long_sphere_scores_grow_from_equator_to_poles(n_lon, n_lat, diagonal):
    corners, uv = lat_long_sphere(n_lon, n_lat)
    m, score = scores(corners.reshape(-1, 4, 3), uv.reshape(-1, 4, 2), diagonal)
    for per_quad in (m, score):
        assert np.isfinite(per_quad).all()
        rows = per_quad.reshape(n_lat, n_lon)
        np.testing.assert_allclose(rows, np.repeat(rows[:, :1], n_lon, axis=1), rtol=1e-6)  # congruent rows
        north = rows[n_lat // 2:, 0]
        south = rows[: n_lat // 2, 0][::-1]
        np.testing.assert_allclose(north, south, rtol=1e-6)
        assert (np.diff(north) > 0).all(), north
        assert north[0] > 0


def test_pole_quad_is_scored_by_the_corners_away_from_the_pole():
    # Corner 2 of the pole triangle predicts corner 3's uv as corner 2's: the
    # split drops half the texture, a quarter of the u span at the centre, and the
    # whole u span at its worst (next to the pole).
    m, score = scores(trapezoid(0.0), UNIT_SQUARE_UV[None])
    np.testing.assert_allclose(m, [0.25])
    np.testing.assert_allclose(score, [np.sqrt(2)])
    error = split_error(planar_quads(trapezoid(0.0)), UNIT_SQUARE_UV[None])
    np.testing.assert_allclose(np.linalg.norm(error, axis=1), [1.0])


def test_collapsed_quads_score_zero_not_nan():
    segment = np.array([[[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]], float)
    point = np.zeros((1, 4, 3))
    for corners in (segment, point):
        m, score = scores(corners, UNIT_SQUARE_UV[None])
        assert m[0] == 0 and score[0] == 0


def test_quad_facing_sideways_scores_like_the_same_quad_facing_the_camera():
    # Listing 3 takes the area sign from v.z, which is 0 for a wall (normal along y).
    facing = trapezoid(0.5)
    wall = facing @ np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], float).T
    assert np.ptp(wall[0, :, 1]) == 0  # the wall lies in a plane y = const
    for diagonal in DIAGONALS:
        np.testing.assert_allclose(
            scores(wall, UNIT_SQUARE_UV[None], diagonal), scores(facing, UNIT_SQUARE_UV[None], diagonal)
        )
    assert scores(wall, UNIT_SQUARE_UV[None])[0][0] > 0.1


def test_attributes_far_from_zero_keep_their_precision():
    corners = trapezoid(1.0) + 1e6  # a rectangle far from the origin
    uv = UNIT_SQUARE_UV * 1e-3 + 1e4
    m, _ = scores(corners, uv[None])
    assert m[0] < 1e-12


def test_diagonal_selection():
    # A kite: diagonal 0-2 short, 1-3 long; corners are skewed so the splits differ.
    corners = np.array([[[0, 0, 0], [2, -1, 0], [2.5, 0, 0], [2, 3, 0]]], float)
    uv = np.array([[[0, 0], [1, 0], [1, 1], [0, 1]]], float)
    quads = planar_quads(corners)
    np.testing.assert_array_equal(selected_corners(quads, "shortest"), [[False, True, False, True]])
    np.testing.assert_array_equal(selected_corners(quads, "13"), [[True, False, True, False]])
    by_diagonal = {d: np.linalg.norm(misplacement(quads, uv, d)) for d in DIAGONALS}
    assert by_diagonal["02"] != pytest.approx(by_diagonal["13"])
    assert by_diagonal["both"] == pytest.approx(max(by_diagonal["02"], by_diagonal["13"]))
    assert by_diagonal["shortest"] == by_diagonal["02"]
    with pytest.raises(ValueError):
        selected_corners(quads, "03")


def test_colours_of_bloomenthal_figure_10_in_steps_of_one_255th():
    square = trapezoid(1.0)
    blue, red, green, black = np.eye(3)[2], np.eye(3)[0], np.eye(3)[1], np.zeros(3)
    yellow, cyan = red + green, green + blue
    seam = misplacement(planar_quads(square), np.array([[blue, red, green, black]]))
    no_seam = misplacement(planar_quads(square), np.array([[blue, red, yellow, cyan]]))
    # (a0 - a1 + a2 - a3) / 4 = (-1, 1, 1) / 4 on a square
    np.testing.assert_allclose(color_steps(seam), [255 * np.sqrt(3) / 4])
    np.testing.assert_allclose(color_steps(no_seam), [0], atol=1e-12)


def test_normal_degrees_is_the_angle_between_split_and_bilinear_normal_at_the_centre():
    square = trapezoid(1.0)
    t = np.radians(30)
    bent = np.array([np.sin(t), 0, np.cos(t)])
    normals = np.array([[[0, 0, 1], bent, [0, 0, 1], bent]], float)
    m = misplacement(planar_quads(square), normals, "02")
    bilinear, split = normals[0].mean(axis=0), (normals[0, 0] + normals[0, 2]) / 2
    angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(bilinear, split)), bilinear @ split))
    np.testing.assert_allclose(normal_degrees(m, normals), [angle])
    np.testing.assert_allclose(angle, 15)  # half the angle between the corner normals


def test_texels_scale_each_axis_by_its_own_size():
    m = np.array([[0.5, 0.0], [0.0, 0.25], [0.003, 0.004]])
    np.testing.assert_allclose(texels(m, 1024), [512, 256, 5.12])
    np.testing.assert_allclose(texels(m, (2048, 512)), [1024, 128, np.hypot(6.144, 2.048)])
