"""render.rasterize_quads: coverage, fill rule, perspective, methods and the
hybrid, each checked against an independent reference (analytic ray-plane
intersections, point-in-polygon tests, renders with the depth order reversed)."""

import numpy as np
import pytest

from render import rasterize_quads
from render.camera import look_at, perspective, to_clip

METHODS = ["split", "mvc", "bilinear", "projective", "exact"]


def pixel_centres(width, height):
    """NDC x, y of every pixel centre, (H, W) each (row 0 at the top)."""
    x = (np.arange(width) + 0.5) * 2 / width - 1
    y = 1 - (np.arange(height) + 0.5) * 2 / height
    return np.meshgrid(x, y)


def pixel_rays(matrix, width, height):
    """The ray through every pixel centre, in world space: its point on the near
    plane (H, W, 3) and the step (H, W, 3) from there to the far plane."""
    x, y = pixel_centres(width, height)
    inverse = np.linalg.inv(matrix)
    near = np.stack([x, y, -np.ones_like(x), np.ones_like(x)], axis=-1) @ inverse.T
    far = np.stack([x, y, np.ones_like(x), np.ones_like(x)], axis=-1) @ inverse.T
    origin = near[..., :3] / near[..., 3:]
    return origin, far[..., :3] / far[..., 3:] - origin


def ground_hits(matrix, width, height):
    """Where the ray through every pixel centre meets the plane y = 0: the ray
    parameter t (H, W) (0 at the near plane, 1 at the far plane, < 0 behind)
    and the point (H, W, 3)."""
    origin, direction = pixel_rays(matrix, width, height)
    t = -origin[..., 1] / direction[..., 1]
    return t, origin + t[..., None] * direction


def grid_quads(nx, ny, rng=None, jitter=0.0, lo=-1.25, hi=1.25):
    """A closed grid of nx * ny screen quads (counter-clockwise) covering [lo, hi]^2.

    Returns corners (Q, 4, 2) and per-corner uv (Q, 4, 2) shared between
    neighbours; interior vertices move by up to ``jitter`` cells.
    """
    gx, gy = np.meshgrid(np.linspace(lo, hi, nx + 1), np.linspace(lo, hi, ny + 1), indexing="ij")
    if jitter:
        cell = (hi - lo) / max(nx, ny)
        gx[1:-1, 1:-1] += rng.uniform(-jitter, jitter, gx[1:-1, 1:-1].shape) * cell
        gy[1:-1, 1:-1] += rng.uniform(-jitter, jitter, gy[1:-1, 1:-1].shape) * cell
    uv = rng.uniform(size=gx.shape + (2,)) if rng is not None else np.stack([gx, gy], axis=-1)
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    i, j = i.ravel(), j.ravel()
    ring = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
    corners = np.stack([np.stack([gx[a, b], gy[a, b]], axis=-1) for a, b in ring], axis=1)
    return corners, np.stack([uv[a, b] for a, b in ring], axis=1)


def flat_clip(corners, depth=0.0):
    """Clip coordinates (w = 1) of screen corners (Q, 4, 2) at NDC depth per quad."""
    q = corners.shape[0]
    z = np.broadcast_to(np.asarray(depth, dtype=float).reshape(-1, 1), (q, 4))
    return np.concatenate([corners, z[..., None], np.ones((q, 4, 1))], axis=2)


def coverage_is_exact(clip, attrs, width, height, method, **kw):
    """True when every pixel is drawn by exactly one quad.

    Quads get distinct depths; the image is drawn twice with the depth order
    reversed. A pixel covered twice shows a different quad in the two images,
    a pixel missed shows -1.
    """
    q = clip.shape[0]
    order = np.linspace(-0.5, 0.5, q)
    a = rasterize_quads(_with_depth(clip, order), attrs, width, height, method, **kw).face
    b = rasterize_quads(_with_depth(clip, -order), attrs, width, height, method, **kw).face
    return (a >= 0).all() and np.array_equal(a, b)


def _with_depth(clip, z):
    clip = clip.copy()
    clip[..., 2] = z[:, None] * clip[..., 3]
    return clip


# ---------------------------------------------------------------- coverage


@pytest.mark.parametrize("method", METHODS)
def test_closed_jittered_grid_covers_every_pixel_exactly_once(method):
    rng = np.random.default_rng(10)
    corners, uv = grid_quads(9, 7, rng, jitter=0.3)
    assert coverage_is_exact(flat_clip(corners), uv, 64, 48, method)


@pytest.mark.parametrize("method", METHODS)
def test_grid_with_edges_through_pixel_centres_covers_every_pixel_exactly_once(method):
    # 16 x 16 pixels, grid lines at x, y = -1.0625 + k * 0.25: exactly through
    # pixel centres (k * 2 pixels + 0.5); diagonals of the cells pass through
    # centres as well.
    corners, uv = grid_quads(9, 9, lo=-1.0625, hi=-1.0625 + 0.25 * 9)
    assert coverage_is_exact(flat_clip(corners), uv, 16, 16, method)


@pytest.mark.parametrize("method", METHODS)
def test_closed_grid_in_perspective_covers_every_pixel_exactly_once(method):
    rng = np.random.default_rng(11)
    corners, uv = grid_quads(8, 8, rng, jitter=0.25, lo=-3, hi=3)
    world = np.concatenate([corners[..., :1], np.zeros_like(corners[..., :1]), corners[..., 1:]], axis=-1)
    matrix = perspective(60, 1.0, 0.1, 20) @ look_at((0.3, 1.5, 4.0), (0, 0, -0.5))
    clip = to_clip(world.reshape(-1, 3), matrix).reshape(-1, 4, 4)
    face = rasterize_quads(clip, uv, 40, 40, method).face
    # No holes: every pixel whose ray meets the ground well inside the grid is drawn.
    t, hit = ground_hits(matrix, 40, 40)
    inside = (t > 0) & (np.abs(hit[..., 0]) < 2.9) & (np.abs(hit[..., 2]) < 2.9)
    assert inside.sum() > 500 and (face[inside] >= 0).all()
    # No double hits: the quads are coplanar, so a pixel drawn twice would go
    # to the first quad drawn, and drawing them in reverse order would change it.
    reverse = rasterize_quads(clip[::-1], uv[::-1], 40, 40, method).face
    assert np.array_equal(np.where(face >= 0, clip.shape[0] - 1 - reverse, -1), face)


def test_top_left_rule_owner_of_shared_edges():
    # Two quads sharing the line x = 0.25, through the centres of column 2 of
    # a 4-pixel-wide image.
    left = [[-1, -1], [0.25, -1], [0.25, 1], [-1, 1]]
    right = [[0.25, -1], [1, -1], [1, 1], [0.25, 1]]
    clip = flat_clip(np.array([left, right], dtype=float))
    face = rasterize_quads(clip, np.zeros((2, 4, 1)), 4, 2).face
    assert face[:, 2].tolist() == [1, 1]  # left edge of the right quad: drawn by it
    # The line y = -0.25, through the centres of row 2 of a 4-row image.
    top = [[-1, -0.25], [1, -0.25], [1, 1], [-1, 1]]
    bottom = [[-1, -1], [1, -1], [1, -0.25], [-1, -0.25]]
    clip = flat_clip(np.array([top, bottom], dtype=float))
    face = rasterize_quads(clip, np.zeros((2, 4, 1)), 2, 4, "mvc").face
    assert face[2].tolist() == [1, 1]  # top edge of the bottom quad: drawn by it
    assert face[1].tolist() == [0, 0]


def test_concave_and_bowtie_quads_fill_exactly_their_outline_with_mvc():
    from matplotlib.path import Path

    width = height = 48
    x, y = pixel_centres(width, height)
    points = np.stack([x.ravel(), y.ravel()], axis=1)
    shapes = {  # corners off the pixel lattice, so no pixel centre is on an edge
        "concave at 3": [[-0.91, -0.87], [0.93, -0.81], [0.82, 0.89], [-0.13, -0.17]],
        "concave at 1": [[-0.91, -0.87], [0.13, -0.17], [0.82, 0.89], [-0.83, 0.81]],
        "concave at 0": [[0.11, 0.19], [0.93, -0.81], [0.82, 0.89], [-0.91, 0.73]],
        "bow-tie": [[-0.81, -0.79], [0.83, 0.77], [0.79, -0.83], [-0.77, 0.81]],
    }
    for name, quad in shapes.items():
        quad = np.array(quad)
        inside = Path(quad).contains_points(points).reshape(height, width)
        # Corners are snapped to 1/256 pixel: pixels that close to the outline may go either way.
        clear = distance_to_outline(points, quad).reshape(height, width) > 2 * (2 / width) / 256
        # The bow-tie outline is two triangles: even-odd and non-zero agree.
        for method in ("mvc", "bilinear", "exact"):
            face = rasterize_quads(flat_clip(quad[None]), np.zeros((1, 4, 1)), width, height, method).face
            assert np.array_equal((face == 0)[clear], inside[clear]), (name, method)
            assert clear.sum() > 0.99 * clear.size


def distance_to_outline(points, quad):
    """Distance (N,) from points (N, 2) to the closed polyline of quad (4, 2)."""
    a, b = quad, np.roll(quad, -1, axis=0)
    d = b - a
    t = np.clip(np.einsum("nkj,kj->nk", points[:, None] - a, d) / np.einsum("kj,kj->k", d, d), 0, 1)
    return np.linalg.norm(points[:, None] - (a + t[..., None] * d), axis=-1).min(axis=1)


def test_back_face_culling():
    ccw = np.array([[[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]])
    cw = ccw[:, ::-1]
    for method in METHODS:
        assert (
            rasterize_quads(flat_clip(ccw), np.zeros((1, 4, 0)), 8, 8, method, cull_backfaces=True).face == 0
        ).any()
        assert (rasterize_quads(flat_clip(cw), np.zeros((1, 4, 0)), 8, 8, method).face == 0).any()
        assert (
            rasterize_quads(flat_clip(cw), np.zeros((1, 4, 0)), 8, 8, method, cull_backfaces=True).face == -1
        ).all()
    # A bow-tie has a front and a back lobe; culling keeps the front one.
    bowtie = np.array([[[-0.8, -0.8], [0.8, 0.8], [0.8, -0.8], [-0.8, 0.8]]])
    x, _ = pixel_centres(16, 16)
    face = rasterize_quads(flat_clip(bowtie), np.zeros((1, 4, 0)), 16, 16, "mvc", cull_backfaces=True).face
    assert (face[:, x[0] < -0.1] == 0).any() and (face[:, x[0] > 0.1] == -1).all()


# ---------------------------------------------------------------- perspective


def tilted_plane_scene(parallelogram=False):
    """A planar quad in 3-D with uv an affine function of position, and its camera."""
    world = np.array([[-1.5, 0.0, 1.0], [1.5, 0.2, 1.2], [1.2, 1.4, -2.5], [-1.4, 1.2, -2.0]])
    if parallelogram:
        world[3] = world[0] + world[2] - world[1]
    else:  # planar, not a parallelogram: corner 3 moved onto the plane of 0, 1, 2
        n = np.cross(world[1] - world[0], world[2] - world[0])
        world[3] = world[3] - (world[3] - world[0]) @ n / (n @ n) * n
    uv_of = np.array([[0.4, -0.1], [0.05, 0.3], [0.2, 0.1]])  # uv = M @ position + offset
    uv = world @ uv_of + np.array([0.5, 0.25])
    view = look_at((0.2, 2.0, 3.5), (0.0, 0.3, -0.5))
    proj = perspective(50, 4 / 3, 0.2, 30)
    return world, uv, proj @ view, uv_of


def analytic_uv(matrix, world, uv_of, width, height):
    """uv of the plane seen through every pixel centre (ray-plane intersection)."""
    origin, direction = pixel_rays(matrix, width, height)
    n = np.cross(world[1] - world[0], world[2] - world[0])
    t = ((world[0] - origin) @ n) / (direction @ n)
    hit = origin + t[..., None] * direction
    return hit @ uv_of + np.array([0.5, 0.25])


@pytest.mark.parametrize(
    "method, parallelogram",
    [("split", False), ("mvc", False), ("exact", False), ("split", True), ("mvc", True), ("exact", True),
     ("projective", True)],
)
def test_perspective_correct_uv_on_tilted_plane(method, parallelogram):
    world, uv, matrix, uv_of = tilted_plane_scene(parallelogram)
    clip = to_clip(world, matrix)[None]
    frame = rasterize_quads(clip, uv[None], 64, 48, method)
    covered = frame.face == 0
    assert covered.sum() > 500
    expected = analytic_uv(matrix, world, uv_of, 64, 48)
    assert np.abs(frame.attrs[covered] - expected[covered]).max() < 1e-9


def test_mvc_equals_split_on_planar_quads_with_affine_attributes():
    rng = np.random.default_rng(12)
    matrix = perspective(55, 1.0, 0.1, 50) @ look_at((0.5, 0.8, 4.0), (0, 0, 0))
    for _ in range(5):
        # A random planar convex quad: a trapezoid-ish outline on a random plane.
        outline = np.array([[-1.0, -0.8], [1.2, -1.0], [0.7, 0.9], [-0.6, 1.1]]) + rng.normal(
            scale=0.1, size=(4, 2)
        )
        a, b = rng.uniform(-1.0, 1.0, size=2)  # tilt the plane by up to about 57 degrees
        tilt = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]]) @ np.array(
            [[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]]
        )
        world = np.hstack([outline, np.zeros((4, 1))]) @ tilt.T + rng.normal(scale=0.3, size=3)
        attrs = world @ rng.normal(size=(3, 3)) + rng.normal(size=3)
        clip = to_clip(world, matrix)[None]
        split = rasterize_quads(clip, attrs[None], 48, 48, "split")
        mvc = rasterize_quads(clip, attrs[None], 48, 48, "mvc")
        assert np.array_equal(split.face, mvc.face)
        covered = split.face == 0
        assert covered.sum() > 50
        assert np.abs(split.attrs[covered] - mvc.attrs[covered]).max() < 1e-9
        assert np.abs(split.depth[covered] - mvc.depth[covered]).max() == 0


def test_shared_edge_between_split_and_mvc_quads_agrees():
    """Pixels on an edge shared by an mvc and a split quad get the same value
    whichever method draws them: the perspective-correct linear interpolation."""
    # Two planar quads in 3-D sharing the edge between corners (0, 1.2, ...).
    a = np.array([[-1.5, -1.0, -1.0], [0.0, -1.0, -1.8], [0.0, 1.0, -2.5], [-1.2, 1.0, -1.5]])
    b = np.array([[0.0, -1.0, -1.8], [1.4, -1.0, -1.0], [1.3, 1.0, -1.2], [0.0, 1.0, -2.5]])
    rng = np.random.default_rng(13)
    shared = rng.uniform(size=(2, 2))  # uv at the two shared vertices
    uv_a = np.vstack([rng.uniform(size=2), shared[0], shared[1], rng.uniform(size=2)])
    uv_b = np.vstack([shared[0], rng.uniform(size=2), rng.uniform(size=2), shared[1]])
    matrix = perspective(70, 1.0, 0.1, 20) @ look_at((0.0, 0.0, 0.2), (0.0, 0.0, -2.0))
    clip = to_clip(np.vstack([a, b]), matrix).reshape(2, 4, 4)
    # The shared edge projects to the vertical line x = 0: the centre line of
    # an image of odd width.
    assert np.allclose(clip[0, 1:3, 0], 0)
    attrs = np.stack([uv_a, uv_b])
    frames = [
        rasterize_quads(clip, attrs, 33, 33, methods) for methods in (["split", "mvc"], ["mvc", "split"])
    ]
    column = frames[0].attrs[:, 16]
    assert np.array_equal(frames[0].face[:, 16], frames[1].face[:, 16])
    assert (frames[0].face[:, 16] >= 0).sum() > 15
    drawn = frames[0].face[:, 16] >= 0
    assert np.abs(column[drawn] - frames[1].attrs[drawn, 16]).max() < 1e-12


def test_projective_reproduces_a_projectively_mapped_square():
    """On a screen quad with unit-square uv, projective is the inverse of the
    homography taking the square to the quad (solved here as an 8 x 8 system)."""
    quad = np.array([[-0.8, -0.7], [0.9, -0.5], [0.4, 0.8], [-0.6, 0.6]])
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    rows, rhs = [], []
    for (u, v), (x, y) in zip(square, quad):
        rows += [[u, v, 1, 0, 0, 0, -u * x, -v * x], [0, 0, 0, u, v, 1, -u * y, -v * y]]
        rhs += [x, y]
    H = np.append(np.linalg.solve(rows, rhs), 1.0).reshape(3, 3)
    x, y = pixel_centres(40, 40)
    back = np.stack([x, y, np.ones_like(x)], axis=-1) @ np.linalg.inv(H).T
    expected = back[..., :2] / back[..., 2:]
    frames = {
        m: rasterize_quads(flat_clip(quad[None]), square[None], 40, 40, m) for m in ("projective", "split")
    }
    covered = frames["projective"].face == 0
    assert covered.sum() > 600
    assert np.abs(frames["projective"].attrs[covered] - expected[covered]).max() < 1e-9
    assert np.abs(frames["split"].attrs[covered] - expected[covered]).max() > 1e-2


# ---------------------------------------------------------------- Bloomenthal's trapezoid


def test_trapezoid_crease_in_split_not_in_mvc():
    """A trapezoid with unit-square uv (Bloomenthal Fig. 3, our construction):
    the split has a jump in the uv gradient across the diagonal 0-2, mvc not."""
    trapezoid = np.array([[[-0.9, -0.8], [0.9, -0.8], [0.3, 0.8], [-0.3, 0.8]]])
    uv = np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]])
    size = 128
    jumps = {}
    for method in ("split", "mvc"):
        frame = rasterize_quads(flat_clip(trapezoid), uv, size, size, method)
        u = frame.attrs[..., 0]
        du = np.diff(u, axis=1)  # finite-difference u gradient along rows
        _, y = pixel_centres(size, size)
        rows = []
        for r in range(30, 98):
            # Where the diagonal from corner 0 to corner 2 crosses this row.
            s = (y[r, 0] + 0.8) / 1.6
            col = round(((-0.9 + s * 1.2) + 1) * size / 2 - 0.5)
            left, right = du[r, col - 6 : col - 3], du[r, col + 3 : col + 6]
            if np.isfinite(left).all() and np.isfinite(right).all():
                rows.append(abs(right.mean() - left.mean()))
        jumps[method] = np.median(rows)
    assert jumps["split"] > 1e-3
    assert jumps["mvc"] < jumps["split"] / 10


# ---------------------------------------------------------------- eye plane


def ground_quad_through_the_eye():
    """A large ground quad with one corner behind the camera, uv affine."""
    # Corner 0 is behind the eye (camera at z = 1 looking towards -z).
    world = np.array([[-3.0, 0.0, 6.0], [3.0, 0.0, 0.5], [3.0, 0.0, -8.0], [-3.0, 0.0, -8.0]])
    uv_of = np.array([[0.1, 0.02], [0.0, 0.0], [0.03, -0.1]])
    uv = world @ uv_of + np.array([0.5, 0.5])
    matrix = perspective(60, 1.0, 0.1, 30) @ look_at((0.0, 1.0, 1.0), (0.0, 0.0, -3.0))
    return world, uv, matrix, uv_of


@pytest.mark.parametrize("method", METHODS)
def test_quad_with_a_corner_behind_the_eye_draws_its_visible_part(method):
    world, uv, matrix, uv_of = ground_quad_through_the_eye()
    clip = to_clip(world, matrix)[None]
    assert (clip[0, :, 3] < 0).sum() == 1
    frame = rasterize_quads(clip, uv[None], 48, 48, method)
    covered = frame.face == 0
    assert not np.isnan(frame.attrs[covered]).any() and not np.isnan(frame.depth[covered]).any()
    # Independent coverage: pixels whose ray hits the ground inside the quad,
    # in front of the near plane (away from the outline by a margin).
    t, hit = ground_hits(matrix, 48, 48)
    ground = hit[..., [0, 2]]
    outline = world[:, [0, 2]]
    edge = np.roll(outline, -1, axis=0) - outline
    # Signed distance to each edge line (the outline is convex, clockwise in x-z).
    offset = ground[..., None, :] - outline
    side = (edge[:, 0] * offset[..., 1] - edge[:, 1] * offset[..., 0]) / np.linalg.norm(edge, axis=1)
    inside = (t > 0.01) & (side < -0.05).all(axis=-1)
    outside = (t < 0) | (side > 0.05).any(axis=-1)
    assert inside.sum() > 300
    assert covered[inside].all() and not covered[outside].any()
    if method != "bilinear":  # bilinear falls back to mvc here, but is not claimed exact
        expected = hit @ uv_of + np.array([0.5, 0.5])
        assert np.abs(frame.attrs[covered] - expected[covered]).max() < 1e-9


@pytest.mark.parametrize("method", METHODS)
def test_corner_exactly_on_the_eye_plane_gives_no_nan(method):
    clip = np.array(
        [[[-0.5, -0.5, 0.0, 1.0], [0.5, -0.5, 0.0, 1.0], [0.3, 0.4, 0.0, 0.0], [-0.5, 0.5, 0.0, 1.0]]]
    )
    clip[0, :, 2] = 0.2 * clip[0, :, 3]
    frame = rasterize_quads(clip, np.arange(8.0).reshape(1, 4, 2), 32, 32, method)
    covered = frame.face == 0
    assert covered.sum() > 100
    assert np.isfinite(frame.attrs[covered]).all() and np.isfinite(frame.depth[covered]).all()


@pytest.mark.parametrize("method", METHODS)
def test_stiff_quads_give_no_nan(method):
    quads = np.array(
        [
            [[-0.9, -0.9], [-0.1, -0.9], [-0.5, -0.1], [-0.5, -0.1]],  # pole: repeated corner
            [[0.1, -0.9], [0.9, -0.9], [0.9, -0.1], [0.1, -0.9]],  # repeated corner 0 = 3
            [[-0.9, 0.1], [0.9, 0.1 + 1e-7], [0.9, 0.12], [-0.9, 0.1]],  # needle
            [[0.1, 0.3], [0.9, 0.9], [0.9, 0.3], [0.1, 0.9]],  # bow-tie
        ]
    )
    frame = rasterize_quads(
        flat_clip(quads), np.random.default_rng(0).uniform(size=(4, 4, 2)), 64, 64, method
    )
    covered = frame.face >= 0
    assert covered.sum() > 300
    assert np.isfinite(frame.attrs[covered]).all()
    assert np.isnan(frame.attrs[~covered]).all() and np.isinf(frame.depth[~covered]).all()


# ---------------------------------------------------------------- the hybrid


def test_per_quad_methods_give_each_quad_its_own_methods_pixels():
    rng = np.random.default_rng(14)
    corners, uv = grid_quads(6, 5, rng, jitter=0.3, lo=-1.1, hi=1.1)
    world = np.concatenate([corners[..., :1], corners[..., 1:] * 0.8, -2.0 - 0.4 * corners[..., 1:]], axis=-1)
    clip = to_clip(
        world.reshape(-1, 3), perspective(60, 1.0, 0.1, 10) @ look_at((0, 0, 0.5), (0, 0, -2))
    ).reshape(-1, 4, 4)
    methods = rng.choice(METHODS, size=clip.shape[0])
    hybrid = rasterize_quads(clip, uv, 48, 40, methods)
    for method in METHODS:
        own = rasterize_quads(clip, uv, 48, 40, method)
        mine = np.isin(hybrid.face, np.flatnonzero(methods == method))
        assert mine.sum() > 50
        assert np.array_equal(hybrid.face[mine], own.face[mine])
        assert np.abs(hybrid.attrs[mine] - own.attrs[mine]).max() < 1e-13
        assert np.array_equal(hybrid.depth[mine], own.depth[mine])


# ---------------------------------------------------------------- frame and input


def test_empty_pixels_and_depth_test():
    near = [[-1, -1], [0.5, -1], [0.5, 0.5], [-1, 0.5]]
    far = [[-0.5, -0.5], [1, -0.5], [1, 1], [-0.5, 1]]
    clip = flat_clip(np.array([far, near], dtype=float), depth=[0.5, -0.5])
    frame = rasterize_quads(clip, np.array([[[1.0]] * 4, [[2.0]] * 4]), 8, 8)
    assert frame.face[2, 3] == 1 and frame.attrs[2, 3, 0] == 2.0 and frame.depth[2, 3] == -0.5
    assert frame.face[0, 7] == 0 and frame.depth[0, 7] == 0.5
    assert frame.face[7, 7] == -1 and np.isnan(frame.attrs[7, 7, 0]) and frame.depth[7, 7] == np.inf


def test_small_batches_give_the_same_image():
    rng = np.random.default_rng(15)
    corners, uv = grid_quads(7, 7, rng, jitter=0.3)
    clip = flat_clip(corners, depth=rng.uniform(-0.5, 0.5, corners.shape[0]))
    for method in METHODS:
        whole = rasterize_quads(clip, uv, 40, 40, method)
        banded = rasterize_quads(clip, uv, 40, 40, method, batch_fragments=50)
        assert np.array_equal(whole.face, banded.face)
        assert np.array_equal(whole.attrs, banded.attrs, equal_nan=True)


def test_bad_input_raises_clear_errors():
    square = flat_clip(np.array([[[-1, -1], [1, -1], [1, 1], [-1, 1]]], dtype=float))
    attrs = np.zeros((1, 4, 2))
    with pytest.raises(ValueError, match="shape"):
        rasterize_quads(square[:, :3], attrs, 4, 4)
    with pytest.raises(ValueError, match="attrs"):
        rasterize_quads(square, attrs[:, :2], 4, 4)
    with pytest.raises(ValueError, match="width"):
        rasterize_quads(square, attrs, 0, 4)
    with pytest.raises(ValueError, match="height"):
        rasterize_quads(square, attrs, 4, 1 << 17)
    with pytest.raises(ValueError, match="batch_fragments"):
        rasterize_quads(square, attrs, 4, 4, batch_fragments=0)
    with pytest.raises(ValueError, match="unknown method"):
        rasterize_quads(square, attrs, 4, 4, "phong")
    bad = square.copy()
    bad[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        rasterize_quads(bad, attrs, 4, 4)
    empty = rasterize_quads(np.zeros((0, 4, 4)), np.zeros((0, 4, 3)), 5, 3)
    assert (empty.face == -1).all() and empty.attrs.shape == (3, 5, 3)
