"""Quad shape measures: own plane, fold (against libigl), degenerate, concave, bow-tie, UV area."""

import numpy as np
import pytest

from affinity.geometry import (
    DEGENERATE_AREA,
    degeneracy,
    fold_degrees,
    folded_fraction,
    interior_angles,
    is_bowtie,
    planar_quads,
    plane_coordinates,
    quad_normals,
    relative_signed_area,
)

SQUARE = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
DART = np.array([[0, 0], [2, 1], [4, 0], [2, 3]], float)  # reflex at corner 1
BOWTIE = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], float)  # symmetric: lobes cancel
BOWTIE_SKEWED = np.array([[0, 0], [2, 0], [0, 1], [1, 1]], float)


def random_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def lift(xy, rotation=np.eye(3), offset=(0, 0, 0)):
    """(4, 2) plane corners -> (1, 4, 3) corners in 3-D: z = 0, then rotated and moved."""
    corners = np.column_stack([xy, np.zeros(len(xy))])
    return (corners @ rotation.T + offset)[None]


def pairwise_distances(points):
    return np.linalg.norm(points[..., :, None, :] - points[..., None, :, :], axis=-1)


def test_plane_coordinates_keep_distances_and_orientation_of_planar_quads():
    rng = np.random.default_rng(1)
    for _ in range(20):
        xy = rng.normal(size=(4, 2))
        xy = xy[np.argsort(np.arctan2(*(xy - xy.mean(0)).T[::-1]))]  # counter-clockwise convex-ish
        corners = lift(xy, random_rotation(rng), rng.normal(size=3) * 100)
        projected = plane_coordinates(corners)
        np.testing.assert_allclose(pairwise_distances(projected), pairwise_distances(xy[None]), atol=1e-9)
        np.testing.assert_allclose(projected.mean(axis=1), 0, atol=1e-9)
        # counter-clockwise in its plane, as the face is wound: positive shoelace area
        x, y = projected[0].T
        assert np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) > 0


def test_normal_follows_the_winding_also_for_quads_facing_sideways():
    np.testing.assert_allclose(quad_normals(lift(SQUARE)), [[0, 0, 2]])
    to_wall = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], float)  # z -> y: the x-z plane
    wall = lift(SQUARE, to_wall)
    np.testing.assert_allclose(quad_normals(wall), [to_wall @ [0, 0, 2]])
    assert (planar_quads(wall).areas > 0).all()


def test_quad_normal_is_the_diagonals_cross_product_and_a_corner_normal_where_they_are_parallel():
    """One quad normal (issue 39): d02 x d13 (numpy's cross product as the reference), and where the
    diagonals are parallel (a symmetric bow-tie: its lobes cancel) the largest corner normal
    (p_k - p_k-1) x (p_k+1 - p_k); the in-plane coordinates use the same normal."""
    rng = np.random.default_rng(39)
    corners = rng.normal(size=(200, 4, 3))
    np.testing.assert_allclose(quad_normals(corners),
                               np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1]), rtol=1e-12,
                               atol=1e-12)
    bowtie = lift(np.array([[0, 0], [2, 1], [2, 0], [0, 1]], float)) @ np.array([[1, 0, 0], [0, 0, 1], [0, 1, 0.0]])
    p = bowtie[0]
    assert np.linalg.norm(np.cross(p[2] - p[0], p[3] - p[1])) < 1e-12  # parallel diagonals
    corner_normals = [np.cross(p[k] - p[k - 1], p[(k + 1) % 4] - p[k]) for k in range(4)]
    expected = max(corner_normals, key=np.linalg.norm)
    np.testing.assert_allclose(quad_normals(bowtie), [expected], atol=1e-12)
    xy = plane_coordinates(bowtie)[0]
    distances = np.linalg.norm(p[:, None] - p[None], axis=-1)
    np.testing.assert_allclose(np.linalg.norm(xy[:, None] - xy[None], axis=-1), distances, atol=1e-12)


def test_fold_of_a_lifted_corner_is_the_closed_form():
    """The unit square with corner 2 lifted by h: along 0-2 the triangle normals are (0, -h, 1) and
    (-h, 0, 1), cos = 1 / (1 + h^2); along 1-3 they are (-h, -h, 1) and (0, 0, 1), cos = 1 / sqrt(1 + 2 h^2)."""
    h = np.array([0.0, 1e-3, 0.3, 1.0, 4.0])
    corners = np.repeat(lift(SQUARE), len(h), axis=0)
    corners[:, 2, 2] = h
    along_02 = np.degrees(np.arccos(1 / (1 + h**2)))
    along_13 = np.degrees(np.arccos(1 / np.sqrt(1 + 2 * h**2)))
    quads = planar_quads(corners)
    np.testing.assert_allclose(fold_degrees(quads, "02"), along_02, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(fold_degrees(quads, "13"), along_13, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(fold_degrees(quads, "both"), along_02, rtol=1e-9, atol=1e-9)  # 0-2 is the worse
    assert fold_degrees(quads, "both")[3] == pytest.approx(60.0)  # Q202's page: the corner lifted by 1


@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e6])
def test_degeneracy(scale):
    square = lift(SQUARE) * scale
    pole = lift(np.array([[0, 0], [1, 0], [0.5, 1], [0.5, 1]])) * scale  # repeated corner
    collapsed_edge = lift(np.array([[0, 0], [1, 0], [1, 1], [1, 1 + 1e-13]])) * scale
    straight_corner = lift(np.array([[0, 0], [1, 0], [2, 0], [1, 1]])) * scale
    segment = lift(np.array([[0, 0], [1, 0], [2, 0], [3, 0]])) * scale
    point = np.zeros((1, 4, 3))
    quads = planar_quads(np.concatenate([square, pole, collapsed_edge, straight_corner, segment, point]))
    values = degeneracy(quads)
    np.testing.assert_allclose(values[0], 0.5)  # smallest split triangle: half the unit square
    assert (values[1:] <= DEGENERATE_AREA).all()
    assert np.isfinite(values).all()


def test_valid_corners_of_a_pole_quad_are_the_two_away_from_the_repeated_corner():
    pole = lift(np.array([[0, 0], [1, 0], [0.5, 1], [0.5, 1]]))
    np.testing.assert_array_equal(planar_quads(pole).valid, [[False, False, True, True]])


def test_interior_angles():
    angles = interior_angles(planar_quads(np.concatenate([lift(SQUARE), lift(DART)])))
    np.testing.assert_allclose(angles[0], 90)
    reflex = 360 - 2 * np.degrees(np.arctan2(2, 1))  # the dart's corner 1: two 1:2 slopes
    np.testing.assert_allclose(angles[1, 1], reflex)
    np.testing.assert_allclose(angles.sum(axis=1), 360)
    straight = interior_angles(planar_quads(lift(np.array([[0, 0], [1, 0], [2, 0], [1, 1]]))))
    np.testing.assert_allclose(straight[0, 1], 180)


def test_interior_angles_of_folded_quads_are_those_of_their_projection_onto_the_quads_plane():
    """Nonplanar quads: the corners projected onto the plane through their centroid with normal
    d02 x d13 (numpy), and the angles between the projected edges (the reference walks the corners;
    the measure reads the plane's areas and dot products). Their sum is 360 for simple quads."""
    rng = np.random.default_rng(203)
    corners = lift(SQUARE) + rng.normal(scale=0.15, size=(300, 4, 3))
    normal = np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    flat = corners - np.einsum("qkd,qd->qk", corners, normal)[..., None] * normal[:, None]
    e_out = np.roll(flat, -1, axis=1) - flat
    e_in = np.roll(e_out, 1, axis=1)
    turn = np.einsum("qkd,qd->qk", np.cross(e_in, e_out), normal)
    expected = 180 - np.degrees(np.arctan2(turn, np.einsum("qkd,qkd->qk", e_in, e_out)))
    quads = planar_quads(corners)
    simple = ~is_bowtie(quads)
    np.testing.assert_allclose(interior_angles(quads)[simple], expected[simple], atol=1e-9)
    np.testing.assert_allclose(interior_angles(quads)[simple].sum(axis=1), 360, atol=1e-9)


def test_concave_and_bowtie_are_told_apart_in_any_orientation():
    rng = np.random.default_rng(3)
    shapes = [SQUARE, DART, BOWTIE, BOWTIE_SKEWED, DART[::-1]]
    wall = np.array([[1, 0, 0], [0, 0, 1], [0, 1, 0]], float)  # the x-z plane, facing sideways
    for rotation in [np.eye(3), wall] + [random_rotation(rng) for _ in range(10)]:
        offset = rng.normal(size=3)
        quads = planar_quads(np.concatenate([lift(s, rotation, offset) for s in shapes]))
        np.testing.assert_array_equal(is_bowtie(quads), [False, False, True, True, False])
        reflex = interior_angles(quads).max(axis=1) > 180
        np.testing.assert_array_equal(reflex[[0, 1, 4]], [False, True, True])


def test_folded_fraction():
    quads = planar_quads(np.concatenate([lift(SQUARE), lift(BOWTIE), lift(BOWTIE_SKEWED)]))
    # skewed bow-tie turns: +2, +2, -1, -1 (twice the corner triangle areas)
    np.testing.assert_allclose(folded_fraction(quads), [0, 0.5, 2 / 6])


def test_relative_signed_area_of_uv_quads():
    uv = np.stack([SQUARE, SQUARE[::-1], SQUARE * 1e-7 + 0.3, np.full((4, 2), 0.5), SQUARE * [1, 1e-12]])
    area = relative_signed_area(planar_quads(uv))
    np.testing.assert_allclose(area[:3], [1, -1, 1])
    assert area[3] == 0 and abs(area[4]) <= DEGENERATE_AREA


def test_an_area_within_rounding_of_zero_is_degenerate():
    """Corner 3 lies 1e-7 off the diagonal 0-2: a sliver of relative area 7e-8 at the origin
    (above Q201's 1e-9), but within rounding of zero for coordinates of 1e9 (ulp 1.2e-7)."""
    from affinity.geometry import degeneracy

    sliver = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0.5, 0.5 + 1e-7, 0]]])
    assert degeneracy(planar_quads(sliver))[0] > 1e-9
    far = planar_quads(sliver + np.array([1e9, -1e9, 0]))
    assert degeneracy(far)[0] == 0
    assert not far.valid[0].all()
    # A unit square there is not degenerate: the rounding area is about 4e-6 of it.
    square = planar_quads(np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]]) + 1e9)
    assert far.rounding[0] < 1e-5 and degeneracy(square)[0] == pytest.approx(0.5)


@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e6])
@pytest.mark.parametrize("diagonal", ["02", "13", "both", "shortest"])
def test_q202_fold_angle_agrees_with_libigl_face_normals(diagonal, scale):
    """The value Q202 reports (geometry.fold_degrees, what affinity check runs) is the angle between
    libigl's normals of the split's two triangles, at any scale."""
    igl = pytest.importorskip("igl")
    from affinity.lint import lint_mesh
    from affinity.mesh import mesh_from_polygons
    from affinity.settings import Settings

    rng = np.random.default_rng(5)
    base = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    corners = base + rng.normal(scale=0.15, size=(400, 4, 3))
    # Convex quads only: on a concave one the fold is taken on the quad's side (a flat dart folds nothing).
    normal = np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1])
    edges = np.roll(corners, -1, axis=1) - corners
    turns = np.einsum("qck,qk->qc", np.cross(edges, np.roll(edges, -1, axis=1)), normal)
    corners = corners[(turns > 0).all(axis=1)][:300] * scale
    mesh = mesh_from_polygons("random", corners.reshape(-1, 3), np.arange(1200).reshape(-1, 4))
    (hits,) = lint_mesh(mesh, Settings(select=["Q202"], thresholds={"Q202": -1.0}, diagonal=diagonal))
    assert hits.faces.tolist() == list(range(300))

    def fold(triangles):
        faces = np.arange(1200).reshape(-1, 4)[:, triangles].reshape(-1, 3)
        normals = igl.per_face_normals(corners.reshape(-1, 3), faces, np.zeros(3)).reshape(-1, 2, 3)
        return np.degrees(np.arccos(np.clip((normals[:, 0] * normals[:, 1]).sum(axis=1), -1, 1)))

    folds = {"02": fold([[0, 1, 2], [0, 2, 3]]), "13": fold([[1, 2, 3], [1, 3, 0]])}
    lengths = np.linalg.norm(corners[:, [2, 3]] - corners[:, [0, 1]], axis=2)
    expected = {**folds, "both": np.maximum(folds["02"], folds["13"]),
                "shortest": np.where(lengths[:, 0] <= lengths[:, 1], folds["02"], folds["13"])}[diagonal]
    np.testing.assert_allclose(hits.values, expected, atol=1e-6)
