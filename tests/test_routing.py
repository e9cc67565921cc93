"""The hybrid's routing rule against hand-computed screen sizes and the sampled split displacement."""

import numpy as np
from helpers.split_reference import random_convex_quad, sampled_sup

from affinity.draw.routing import (
    clip_components,
    displacement_pixels,
    route_by_view,
    screen_area,
    uv_displacement,
)

UNIT_UV = np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]])
TRAPEZOID_UV = np.array([[[0.0, 0.0], [1.0, 0.0], [0.75, 1.0], [0.25, 1.0]]])


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
    np.testing.assert_allclose(screen_area(clip_components(square_clip(0.5)), 200, 100), [5000.0])
    np.testing.assert_allclose(screen_area(clip_components(square_clip(0.5, ccw=False)), 200, 100), [-5000.0])
    # w divides out:
    np.testing.assert_allclose(screen_area(clip_components(square_clip(0.5, w=3.0)), 200, 100), [5000.0])
    behind = square_clip(0.5)
    behind[0, 2, 3] = -1.0
    assert np.isnan(screen_area(clip_components(behind), 200, 100)[0])


def test_displacement_equals_the_sampled_split_displacement_under_an_affine_camera():
    """With w = 1 the screen is an affine image of the quad, so the pixel displacement is the
    largest |split - bilinear| of the screen positions over the uv quad (roles swapped)."""
    rng = np.random.default_rng(4)
    for _ in range(10):
        uv = random_convex_quad(rng)
        screen = rng.uniform(-0.8, 0.8, size=(4, 2))
        clip = np.zeros((1, 4, 4))
        clip[0, :, :2], clip[0, :, 3] = screen, 1.0
        pixels = displacement_pixels(uv_displacement(uv[None]), clip_components(clip), 200, 100)[0]
        uv3 = np.column_stack([uv, np.zeros(4)])
        expected = sampled_sup(uv3, screen * [100, 50], "02")
        np.testing.assert_allclose(pixels, expected, rtol=0.01)


def test_routing_sends_only_visible_displacements_to_mvc():
    # A square of 100 x 100 pixels carrying a trapezoid of uv: the split moves the texture by
    # (1 - r) / (1 + sqrt r)^2 of the quad's width along u, r = 1/2 the uv trapezoid's side ratio.
    pixels = displacement_pixels(uv_displacement(TRAPEZOID_UV), clip_components(square_clip(0.5)), 200, 200)
    np.testing.assert_allclose(pixels, [100 * 0.5 / (1 + np.sqrt(0.5)) ** 2], rtol=1e-9)
    clip = np.concatenate([square_clip(0.5), square_clip(0.5), square_clip(0.001), square_clip(0.5, ccw=False)])
    uv = np.concatenate([TRAPEZOID_UV, UNIT_UV, TRAPEZOID_UV, TRAPEZOID_UV])
    moves = uv_displacement(uv)
    np.testing.assert_array_equal(route_by_view(moves, uv, clip, 200, 200), ["mvc", "split", "split", "mvc"])
    np.testing.assert_array_equal(route_by_view(moves, uv, clip, 200, 200, cull_backfaces=True),
                                  ["mvc", "split", "split", "split"])
    assert route_by_view(moves, uv, clip, 200, 200, pixel_tolerance=18)[0] == "split"  # 17.2 px
    off_screen = square_clip(0.5)
    off_screen[0, :, 0] += 5.0
    assert route_by_view(uv_displacement(TRAPEZOID_UV), TRAPEZOID_UV, off_screen, 200, 200)[0] == "split"


def test_affine_quads_stay_split_even_across_the_near_plane():
    clip = square_clip(0.5)
    clip[0, :, 3] = [-0.5, 1.0, 2.5, 1.0]  # still a parallelogram in clip space, one corner behind the eye
    assert route_by_view(uv_displacement(UNIT_UV), UNIT_UV, clip, 64, 64)[0] == "split"
    assert route_by_view(uv_displacement(TRAPEZOID_UV), TRAPEZOID_UV, clip, 64, 64)[0] == "mvc"
    near = square_clip(0.5)
    near[0, 1, 2] = -2.0  # z < -w: in front of the eye but nearer than the near plane
    assert route_by_view(uv_displacement(TRAPEZOID_UV), TRAPEZOID_UV, near, 64, 64)[0] == "mvc"


def test_folded_uv_goes_to_mvc_and_degenerate_uv_by_the_lint_error():
    folded = np.array([[[0.0, 0.0], [0.3, 0.6], [1.0, 1.0], [0.0, 1.0]]])  # corner 1 reflex: (0, 1, 2) clockwise
    moves = uv_displacement(folded)
    assert moves.folded[0] and route_by_view(moves, folded, square_clip(0.5), 200, 200)[0] == "mvc"
    line = np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0]]])  # Q301: no area in uv
    moves = uv_displacement(line)
    assert moves.degenerate[0] and not moves.folded[0]
    # 100 x 100 pixels over a uv extent of 1 (longest edge): 100 px per uv unit.
    assert route_by_view(moves, line, square_clip(0.5), 200, 200, uv_error=np.array([0.004]))[0] == "split"
    assert route_by_view(moves, line, square_clip(0.5), 200, 200, uv_error=np.array([0.006]))[0] == "mvc"
    assert route_by_view(moves, line, square_clip(0.5), 200, 200)[0] == "split"


def test_screen_area_equals_the_shoelace_sum_on_any_quad():
    rng = np.random.default_rng(7)
    clip = rng.normal(size=(200, 4, 4))
    clip[..., 3] = rng.uniform(0.5, 2.0, size=(200, 4))  # in front of the eye; convex, concave and bow-ties
    x, y = clip[..., 0] / clip[..., 3] * 32.0, clip[..., 1] / clip[..., 3] * 24.0
    shoelace = 0.5 * (x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y).sum(axis=1)
    np.testing.assert_allclose(screen_area(clip_components(clip), 64, 48), shoelace, rtol=1e-10, atol=1e-10)
