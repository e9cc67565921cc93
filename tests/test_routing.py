"""The hybrid's routing rule against hand-computed screen sizes."""

import numpy as np

from affinity.draw.routing import attribute_area, route_by_view, screen_area, split_error_pixels

UNIT_UV = np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]])


def square_clip(half: float, w: float = 1.0, ccw: bool = True) -> np.ndarray:
    xy = np.array([[-half, -half], [half, -half], [half, half], [-half, half]])
    if not ccw:
        xy = xy[::-1]
    clip = np.zeros((1, 4, 4))
    clip[0, :, :2] = xy * w
    clip[0, :, 3] = w
    return clip


def test_screen_area_of_a_centred_square():
    # NDC half-size 0.5 on a 200x100 image: 100 x 50 pixels, counter-clockwise.
    np.testing.assert_allclose(screen_area(square_clip(0.5), 200, 100), [5000.0])
    np.testing.assert_allclose(screen_area(square_clip(0.5, ccw=False), 200, 100), [-5000.0])
    np.testing.assert_allclose(screen_area(square_clip(0.5, w=3.0), 200, 100), [5000.0])  # w divides out
    behind = square_clip(0.5)
    behind[0, 2, 3] = -1.0
    assert np.isnan(screen_area(behind, 200, 100)[0])


def test_error_is_misplacement_times_pixels_per_uv_unit():
    # 100 x 100 pixel square showing the unit uv square: 100 px per uv unit.
    error = split_error_pixels(np.array([0.01]), UNIT_UV, screen_area(square_clip(0.5), 200, 200))
    np.testing.assert_allclose(error, [1.0])
    np.testing.assert_allclose(attribute_area(UNIT_UV * 2), [4.0])


def test_routing_sends_only_visible_errors_to_mvc():
    clip = np.concatenate([square_clip(0.5), square_clip(0.5), square_clip(0.001), square_clip(0.5, ccw=False)])
    uv = np.repeat(UNIT_UV, 4, axis=0)
    m = np.array([0.01, 0.001, 0.5, 0.01])  # 1 px, 0.1 px, tiny quad, back-facing 1 px
    np.testing.assert_array_equal(route_by_view(m, uv, clip, 200, 200), ["mvc", "split", "split", "mvc"])
    np.testing.assert_array_equal(
        route_by_view(m, uv, clip, 200, 200, cull_back_faces=True), ["mvc", "split", "split", "split"]
    )
    off_screen = square_clip(0.5)
    off_screen[0, :, 0] += 5.0
    assert route_by_view(m[:1], UNIT_UV, off_screen, 200, 200)[0] == "split"


def test_affine_quads_stay_split_even_across_the_eye_plane():
    clip = square_clip(0.5)
    clip[0, 0, 3] = -0.5
    assert route_by_view(np.array([0.0]), UNIT_UV, clip, 64, 64)[0] == "split"
    assert route_by_view(np.array([1e-6]), UNIT_UV, clip, 64, 64)[0] == "mvc"


def test_screen_area_equals_the_shoelace_sum_on_any_quad():
    rng = np.random.default_rng(7)
    clip = rng.normal(size=(200, 4, 4))
    clip[..., 3] = rng.uniform(0.5, 2.0, size=(200, 4))  # in front of the eye; convex, concave and bow-ties
    x, y = clip[..., 0] / clip[..., 3] * 32.0, clip[..., 1] / clip[..., 3] * 24.0
    shoelace = 0.5 * (x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y).sum(axis=1)
    np.testing.assert_allclose(screen_area(clip, 64, 48), shoelace, rtol=1e-10, atol=1e-10)
