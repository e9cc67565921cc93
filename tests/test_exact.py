"""The ``exact`` method against an independent reference, and where the other methods agree with it.

The reference (``reference_hits``) intersects each pixel's eye ray with the
bilinear patch in *world* space, in 40-digit mpmath arithmetic, by another
elimination than the renderer's: the ray meets the patch at parameter s when
it is coplanar with the segment P(s, 0) P(s, 1), a quadratic in s (Reshetov's
"cool patches" route); t and the ray distance then follow from a 2x2 system.
The renderer instead works in clip space and eliminates s first.
"""

import mpmath as mp
import numpy as np
import pytest

from render import orthographic, rasterize_quads, to_clip
from render.camera import look_at, perspective
from render.patch import ray_patch_parameters

TOLERANCE = 1e-9


def pixel_ray(inverse, px, py):
    """World-space origin (on the near plane) and direction (towards the far plane) of an NDC pixel centre."""
    ends = []
    for z in (-1, 1):
        h = inverse * mp.matrix([px, py, z, 1])
        ends.append(mp.matrix([h[0] / h[3], h[1] / h[3], h[2] / h[3]]))
    return ends[0], ends[1] - ends[0]


def patch_hits(world, origin, direction):
    """Every (s, t, distance) with P(s, t) = origin + distance * direction, (s, t) in the unit square, distance > 0."""
    P = [mp.matrix([mp.mpf(float(v)) for v in p]) for p in world]
    A0, A1 = P[0] - origin, P[1] - P[0]  # P(s, 0) - origin = A0 + s A1
    B0, B1 = P[3] - origin, P[2] - P[3]  # P(s, 1) - origin = B0 + s B1

    def triple(u, v):
        return mp.fdot(
            [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]], direction
        )

    c2, c1, c0 = triple(A1, B1), triple(A0, B1) + triple(A1, B0), triple(A0, B0)
    if abs(c2) < mp.mpf(10) ** -30 * (abs(c1) + abs(c0)):
        roots = [-c0 / c1]
    else:
        disc = c1 * c1 - 4 * c2 * c0
        roots = [] if disc < 0 else [(-c1 + sign * mp.sqrt(disc)) / (2 * c2) for sign in (1, -1)]
    hits = []
    eps = mp.mpf(10) ** -20
    for s in roots:
        if not -eps <= s <= 1 + eps:
            continue
        bottom = P[0] + s * (P[1] - P[0])
        rung = P[3] + s * (P[2] - P[3]) - bottom  # P(s, t) = bottom + t rung
        # bottom + t rung = origin + distance direction: least squares on the three components.
        M = mp.matrix([[rung[i], -direction[i]] for i in range(3)])
        t, distance = mp.lu_solve(M.T * M, M.T * (origin - bottom))
        if -eps <= t <= 1 + eps and distance > 0:
            hits.append((s, t, distance))
    return hits


def reference_attributes(world, attrs, matrix, width, height, pixels):
    """Bilinear interpolation of attrs (4, K) at the nearest hit of each pixel (row, col) of ``pixels``.

    Returns (N, K) float64 and how many pixels had two hits.
    """
    mp.mp.dps = 40
    inverse = mp.inverse(mp.matrix(matrix.tolist()))
    values, double = [], 0
    for row, col in pixels:
        px = (mp.mpf(int(col)) + mp.mpf(1) / 2) * 2 / width - 1
        py = 1 - (mp.mpf(int(row)) + mp.mpf(1) / 2) * 2 / height
        hits = patch_hits(world, *pixel_ray(inverse, px, py))
        assert hits, (row, col)
        double += len(hits) > 1
        s, t, _ = min(hits, key=lambda hit: hit[2])
        weights = [(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t]
        values.append([float(mp.fsum(w * mp.mpf(float(a)) for w, a in zip(weights, column))) for column in attrs.T])
    return np.array(values), double


def render_and_reference(world, attrs, matrix, width, height, method="exact"):
    frame = rasterize_quads(to_clip(world, matrix)[None], attrs[None], width, height, method)
    pixels = np.argwhere(frame.face == 0)
    expected, double = reference_attributes(world, attrs, matrix, width, height, pixels)
    return frame.attrs[frame.face == 0], expected, double


ATTRS = np.array([[0.1, 3.0, -1.0], [0.9, -2.0, 0.5], [0.3, 1.0, 4.0], [0.7, 0.0, 2.0]])  # not affine
TRAPEZOID = np.array([[-1.5, 0.0, 1.0], [1.5, 0.2, 1.2], [0.6, 1.4, -2.5], [-0.8, 1.2, -2.0]])


def planar(world):
    """``world`` (4, 3) with corner 3 moved onto the plane of corners 0, 1, 2."""
    world = world.copy()
    n = np.cross(world[1] - world[0], world[2] - world[0])
    world[3] -= (world[3] - world[0]) @ n / (n @ n) * n
    return world


def test_exact_is_bilinear_interpolation_on_a_planar_quad_in_perspective():
    matrix = perspective(50, 4 / 3, 0.2, 30) @ look_at((0.2, 2.0, 3.5), (0.0, 0.3, -0.5))
    got, expected, _ = render_and_reference(planar(TRAPEZOID), ATTRS, matrix, 32, 24)
    assert len(got) > 150
    assert np.abs(got - expected).max() < TOLERANCE


SADDLE = np.array([[-1.0, -1.0, 1.6], [1.0, -1.0, -1.6], [1.0, 1.0, 1.6], [-1.0, 1.0, -1.6]])  # z = 1.6 x y


def test_exact_is_bilinear_interpolation_on_a_nonplanar_patch():
    matrix = perspective(60, 1.0, 0.1, 30) @ look_at((3.2, 0.4, 0.3), (0.0, 0.0, 0.0), up=(0, 0, 1))
    got, expected, double = render_and_reference(SADDLE, ATTRS, matrix, 28, 28)
    assert len(got) > 150
    # Inside the screen outline the patch's projection has degree one and a line
    # meets the patch at most twice, so every covered pixel has exactly one hit.
    assert double == 0
    assert np.abs(got - expected).max() < TOLERANCE


def test_exact_on_a_triangle_passed_as_a_quad_is_barycentric_interpolation():
    # A repeated last corner collapses edge 2-3: every s is the same point there, and
    # eliminating s brings in the spurious root t = 1, which must not be taken, although
    # its point (corner 2, here the nearest) is nearer than the true hit.
    world = np.array([[-2.0, 1.5, -2.0], [2.0, 1.3, -2.5], [0.1, -0.3, 1.5], [0.1, -0.3, 1.5]])
    matrix = perspective(50, 4 / 3, 0.2, 30) @ look_at((0.2, 2.0, 3.5), (0.0, 0.3, -0.5))
    clip = to_clip(world, matrix)[None]
    attrs = ATTRS[[0, 1, 2, 2]]
    exact, split = (rasterize_quads(clip, attrs[None], 64, 48, m) for m in ("exact", "split"))
    covered = exact.face == 0
    assert covered.sum() > 400 and np.array_equal(covered, split.face == 0)
    # Away from the outline by more than the fixed-point snapping (there exact clamps onto the edge).
    x = (clip[0, :3, 0] / clip[0, :3, 3] + 1) * 32 - 0.5
    y = (1 - clip[0, :3, 1] / clip[0, :3, 3]) * 24 - 0.5
    col, row = np.meshgrid(np.arange(64.0), np.arange(48.0))
    dx, dy = np.roll(x, -1) - x, np.roll(y, -1) - y
    distance = np.abs((col[..., None] - x) * dy - (row[..., None] - y) * dx) / np.hypot(dx, dy)
    inner = covered & (distance.min(axis=-1) > 0.01)
    assert inner.sum() > 0.9 * covered.sum()
    assert np.abs(exact.attrs[inner] - split.attrs[inner]).max() < TOLERANCE


def test_ray_patch_parameters_take_the_nearest_hit_and_report_misses():
    # Seen along its rising diagonal, the saddle folds: outside its screen outline
    # some rays cross it twice and some miss it.
    n = 20
    matrix = perspective(60, 1.0, 0.1, 30) @ look_at((3.0, 3.0, 0.6), (0.0, 0.0, 0.3), up=(0, 0, 1))
    rows, cols = np.divmod(np.arange(n * n), n)
    px, py = (cols + 0.5) * 2 / n - 1, 1 - (rows + 0.5) * 2 / n
    corners = np.repeat(to_clip(SADDLE, matrix).T[..., None], n * n, axis=2)
    s, t, hit = ray_patch_parameters(corners, px, py)
    mp.mp.dps = 40
    inverse = mp.inverse(mp.matrix(matrix.tolist()))
    found = {0: 0, 1: 0, 2: 0}
    for k in range(n * n):
        hits = patch_hits(SADDLE, *pixel_ray(inverse, mp.mpf(px[k]), mp.mpf(py[k])))
        found[len(hits)] += 1
        assert hit[k] == bool(hits), k
        if hits:
            nearest = min(hits, key=lambda h: h[2])
            assert abs(s[k] - float(nearest[0])) < TOLERANCE and abs(t[k] - float(nearest[1])) < TOLERANCE, k
    assert found[2] > 10 and found[0] > 10 and found[1] > 10
    assert ((0 <= s) & (s <= 1) & (0 <= t) & (t <= 1)).all()


def test_ray_patch_parameters_clamp_a_miss_into_the_square():
    square = np.array([[-1, 1, 1, -1], [-1, -1, 1, 1], [0, 0, 0, 0], [2, 2, 2, 2]], float)[..., None]
    px, py = np.array([0.0, 0.7, -0.5]), np.array([0.0, 0.0, 0.5])
    s, t, hit = ray_patch_parameters(np.repeat(square, 3, axis=2), px, py)
    assert hit.tolist() == [True, False, True]  # NDC x = 0.7 is beyond the square's edge at 0.5
    assert s.tolist() == [0.5, 1.0, 0.0] and t.tolist() == [0.5, 0.5, 1.0]


def affine_scene(parallelogram):
    """A planar quad with attributes affine in position, K = 3."""
    world = planar(TRAPEZOID)
    if parallelogram:
        world[3] = world[0] + world[2] - world[1]
    attrs = world @ np.array([[0.4, -0.1, 1.0], [0.05, 0.3, -2.0], [0.2, 0.1, 0.5]]) + np.array([0.5, 0.25, 3.0])
    return world, attrs


@pytest.mark.parametrize("parallelogram", [False, True])
def test_split_mvc_exact_agree_on_affine_attributes_in_perspective(parallelogram):
    world, attrs = affine_scene(parallelogram)
    matrix = perspective(50, 4 / 3, 0.2, 30) @ look_at((0.2, 2.0, 3.5), (0.0, 0.3, -0.5))
    clip = to_clip(world, matrix)[None]
    methods = ["split", "mvc", "exact"] + (["projective"] if parallelogram else [])
    frames = {m: rasterize_quads(clip, attrs[None], 64, 48, m) for m in methods}
    covered = frames["exact"].face == 0
    assert covered.sum() > 800
    for method in methods:
        assert np.array_equal(frames[method].face == 0, covered) or method in ("split", "projective")
        both = covered & (frames[method].face == 0)
        assert both.sum() > 0.99 * covered.sum()
        assert np.abs(frames[method].attrs[both] - frames["exact"].attrs[both]).max() < TOLERANCE, method
    if not parallelogram:  # projective maps a parallelogram, not this trapezoid's affine field
        projective = rasterize_quads(clip, attrs[None], 64, 48, "projective")
        assert np.abs(projective.attrs[covered] - frames["exact"].attrs[covered]).max() > 1e-3


@pytest.mark.parametrize("view", ["orthographic", "facing"])
def test_bilinear_equals_exact_when_every_corner_has_the_same_w(view):
    if view == "orthographic":  # w = 1 everywhere, on a tilted quad
        world = planar(TRAPEZOID)
        matrix = orthographic(2.0, 4 / 3, 0.1, 20) @ look_at((0.5, 2.5, 4.0), (0.0, 0.5, -0.5))
    else:  # perspective, the quad parallel to the image plane: one w for all corners
        world = np.array([[-1.5, -1.0, -3.0], [1.4, -1.1, -3.0], [0.6, 1.2, -3.0], [-0.9, 0.9, -3.0]])
        matrix = perspective(60, 4 / 3, 0.2, 30) @ look_at((0, 0, 0), (0, 0, -1))
    clip = to_clip(world, matrix)[None]
    assert np.ptp(clip[0, :, 3]) < 1e-12
    exact = rasterize_quads(clip, ATTRS[None], 64, 48, "exact")
    bilinear = rasterize_quads(clip, ATTRS[None], 64, 48, "bilinear")
    covered = exact.face == 0
    assert covered.sum() > 500 and np.array_equal(bilinear.face == 0, covered)
    assert np.abs(bilinear.attrs[covered] - exact.attrs[covered]).max() < TOLERANCE
    # With the same w the two agree; in perspective on a tilted quad they do not.
    tilted = to_clip(planar(TRAPEZOID), perspective(50, 4 / 3, 0.2, 30) @ look_at((0.2, 2.0, 3.5), (0, 0.3, -0.5)))
    far_apart = [rasterize_quads(tilted[None], ATTRS[None], 64, 48, m).attrs for m in ("exact", "bilinear")]
    assert np.nanmax(np.abs(far_apart[0] - far_apart[1])) > 1e-2
