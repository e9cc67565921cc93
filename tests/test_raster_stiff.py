"""render.rasterize_quads on stiff clip-space quads (issue 11): a corner on the eye
plane, quads crossing it, pole quads, needles, bow-ties, tiny and huge clip
coordinates. Every method must cover pixels and give finite attributes and
depth on every covered pixel; where all weights are convex combinations (planar
quads in front of the eye), attributes stay within the corners' range."""

import numpy as np
import pytest

from render import rasterize_quads
from render.camera import look_at, perspective, to_clip

METHODS = ["split", "mvc", "bilinear"]
SIZE = 48


def clip_of(corners, w=None, depth=0.3):
    """Clip coordinates (1, 4, 4) of NDC corners (4, 2) at homogeneous w (4,)."""
    corners = np.asarray(corners, dtype=float)
    w = np.ones(4) if w is None else np.asarray(w, dtype=float)
    return np.concatenate([corners * w[:, None], depth * w[:, None], w[:, None]], axis=1)[None]


def pixel_row_centre(row, height=SIZE):
    return 1 - (row + 0.5) * 2 / height


def ground_quad(behind):
    """A planar ground quad (y = 0) seen from (0, 1, 1) looking down -z with
    ``behind`` corners behind the eye, and its clip coordinates."""
    world = np.array([[-2.0, 0.0, -6.0], [2.0, 0.0, -6.0], [1.5, 0.0, 3.0], [-1.5, 0.0, 3.0]])
    if behind == 1:
        world[3] = [-1.5, 0.0, -1.0]
    matrix = perspective(70, 1.0, 0.1, 50) @ look_at((0.0, 1.0, 1.0), (0.0, 0.0, -3.0))
    clip = to_clip(world, matrix)[None]
    assert (clip[0, :, 3] < 0).sum() == behind
    return clip


def pole_fan(n=12):
    """A lat-long sphere's cap seen from above at an angle: n pole quads whose last
    corner repeats the pole (a triangle as a quad), clip (n, 4, 4)."""
    phi = np.linspace(0, 2 * np.pi, n + 1)
    ring = np.stack([0.6 * np.cos(phi), np.full_like(phi, 0.8), 0.6 * np.sin(phi)], axis=1)
    pole = np.array([0.0, 1.0, 0.0])
    world = np.stack([np.stack([ring[k], ring[k + 1], pole, pole]) for k in range(n)])
    matrix = perspective(50, 1.0, 0.1, 20) @ look_at((0.4, 2.6, 1.6), (0.0, 0.9, 0.0))
    return to_clip(world.reshape(-1, 3), matrix).reshape(n, 4, 4)


def needle(aspect, angle):
    """A thin trapezoid through the centre row of pixels, of the given aspect, rotated by
    angle. Its width, 1/25 pixel, stays above the rasterizer's 1/256-pixel snapping; long
    needles reach far off screen (clipped to the guard band)."""
    y = pixel_row_centre(SIZE // 2)
    h = 2.0 / SIZE / 25
    half = h * aspect / 2
    corners = np.array([[-half, -h / 2], [half, -0.3 * h], [half, 0.3 * h], [-half, h / 2]])
    c, s = np.cos(angle), np.sin(angle)
    corners = corners @ np.array([[c, s], [-s, c]]) + [0.0, y]
    return clip_of(corners, [1.0, 2.0, 2.0, 1.0])


SCENES = {
    "corner on the eye plane": np.array([[[-0.6, -0.6, 0.3, 1.0], [0.6, -0.5, 0.3, 1.0], [0.3, 0.4, 0.0, 0.0],
                                          [-0.5, 0.6, 0.3, 1.0]]]),
    "corner just behind the eye plane": clip_of([[-0.6, -0.6], [0.6, -0.5], [0.3, 0.4], [-0.5, 0.6]],
                                                [1.0, 1.5, -1e-9, 0.8]),
    "ground quad, one corner behind the eye": ground_quad(1),
    "ground quad, two corners behind the eye": ground_quad(2),
    "pole fan (repeated corners)": pole_fan(),
    "needle 1e3": needle(1e3, 0.0),
    "needle 1e6": needle(1e6, 0.0),
    "needle 1e4, tilted": needle(1e4, 1e-5),
    "needle 1e3 diagonal": clip_of(np.array([[-0.8, -0.8], [0.8, 0.8 - 2e-3], [0.8, 0.8], [-0.8, -0.8 + 1e-3]])),
    "bow-tie": clip_of([[-0.7, -0.6], [0.7, 0.6], [0.7, -0.6], [-0.7, 0.6]], [1.0, 3.0, 0.5, 2.0]),
    "bow-tie crossing at a pixel centre": clip_of([[-0.5, -0.5], [0.5, 0.5], [0.5, -0.5], [-0.5, 0.5]]
                                                  + np.array([1, 1]) / SIZE),
    "tiny clip coordinates (w = 1e-12)": clip_of([[-0.7, -0.6], [0.6, -0.7], [0.5, 0.6], [-0.6, 0.4]],
                                                 [1e-12, 2e-12, 1e-12, 3e-12]),
    "huge clip coordinates (w = 1e12)": clip_of([[-0.7, -0.6], [0.6, -0.7], [0.5, 0.6], [-0.6, 0.4]],
                                                [1e12, 2e12, 1e12, 3e12]),
    "near-parallelogram (defect 1e-12)": clip_of([[-0.7, -0.6], [0.5, -0.5], [0.7, 0.6 + 1e-12], [-0.5, 0.5]]),
    "sub-pixel quad around a pixel centre": clip_of(np.array([[-1, -1], [1, -0.8], [0.9, 1], [-1, 0.7]]) / SIZE / 16
                                                    + [(SIZE // 2 + 0.5) * 2 / SIZE - 1, pixel_row_centre(SIZE // 2)]),
}
#: Scenes whose weights are convex combinations in 3-D (planar, convex outline in front of or
#: through the eye): their attributes stay within the corners' range.
CONVEX = {"ground quad, one corner behind the eye", "ground quad, two corners behind the eye",
          "tiny clip coordinates (w = 1e-12)", "huge clip coordinates (w = 1e12)",
          "near-parallelogram (defect 1e-12)", "needle 1e3", "corner just behind the eye plane"}


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("scene", SCENES)
def test_stiff_clip_space_quads_give_finite_attributes_on_covered_pixels(scene, method):
    clip = SCENES[scene]
    attrs = np.random.default_rng(0).uniform(-1, 1, size=clip.shape[:2] + (3,))
    frame = rasterize_quads(clip, attrs, SIZE, SIZE, method)
    covered = frame.face >= 0
    assert covered.any(), "the quad covers pixel centres"
    assert np.isfinite(frame.attrs[covered]).all()
    assert np.isfinite(frame.depth[covered]).all()
    if scene in CONVEX and method != "bilinear":  # bilinear is screen-space: not a 3-D combination
        lo, hi = attrs[0].min(axis=0), attrs[0].max(axis=0)
        values = frame.attrs[covered]
        assert (values >= lo - 1e-9).all() and (values <= hi + 1e-9).all()


def test_clip_scale_does_not_change_the_image():
    """Clip coordinates are homogeneous: scaling a quad's corners by 1e-12 or 1e12
    draws the same pixels with the same attributes (to rounding)."""
    corners = [[-0.7, -0.6], [0.6, -0.7], [0.5, 0.6], [-0.6, 0.4]]
    w = np.array([1.0, 2.0, 1.0, 3.0])
    attrs = np.random.default_rng(1).uniform(size=(1, 4, 2))
    for method in METHODS:
        base = rasterize_quads(clip_of(corners, w), attrs, SIZE, SIZE, method)
        for scale in (1e-12, 1e12):
            moved = rasterize_quads(clip_of(corners, w * scale), attrs, SIZE, SIZE, method)
            assert np.array_equal(moved.face, base.face), (method, scale)
            covered = base.face >= 0
            assert np.abs(moved.attrs[covered] - base.attrs[covered]).max() < 1e-12, (method, scale)
