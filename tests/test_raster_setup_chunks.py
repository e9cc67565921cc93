"""rasterize_quads sets quads up in chunks of ``render.raster.SETUP_QUADS``: the frame must not
depend on where the chunks end (triangle numbering, draw order, depth ties)."""

import numpy as np
import pytest

import render.raster
from render import rasterize_quads
from render.camera import look_at, perspective, to_clip

METHODS = ["split", "mvc", "bilinear", "projective", "exact"]


def perspective_grid(n=9, seed=3):
    """A jittered n x n grid of ground quads in perspective: clip (Q, 4, 4) and uv (Q, 4, 2)."""
    rng = np.random.default_rng(seed)
    x, z = np.meshgrid(np.linspace(-2, 2, n + 1), np.linspace(-3, 1, n + 1), indexing="ij")
    x[1:-1, 1:-1] += rng.uniform(-0.1, 0.1, (n - 1, n - 1))
    points = np.stack([x, 0.1 * np.sin(3 * x + z), z], axis=-1)
    uv = rng.uniform(size=x.shape + (2,))
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), indexing="ij"))
    ring = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)]
    corners = np.stack([points[a, b] for a, b in ring], axis=1)
    matrix = perspective(60, 1.0, 0.1, 20) @ look_at((0.2, 2.0, 3.0), (0, 0, -1))
    return to_clip(corners.reshape(-1, 3), matrix).reshape(-1, 4, 4), np.stack([uv[a, b] for a, b in ring], axis=1)


@pytest.mark.parametrize("method", METHODS)
def test_frame_does_not_depend_on_the_setup_chunks(method, monkeypatch):
    clip, uv = perspective_grid()
    whole = rasterize_quads(clip, uv, 48, 40, method)
    monkeypatch.setattr(render.raster, "SETUP_QUADS", 5)  # 81 quads: 17 chunks, the last one short
    chunked = rasterize_quads(clip, uv, 48, 40, method)
    assert (whole.face >= 0).sum() > 500
    assert np.array_equal(whole.face, chunked.face)
    assert np.array_equal(whole.attrs, chunked.attrs, equal_nan=True)
    assert np.array_equal(whole.depth, chunked.depth)


@pytest.mark.parametrize("one_quad_each", ["SETUP_QUADS", "BATCH_QUADS"])
@pytest.mark.parametrize("method", ["mvc", "split"])
def test_depth_ties_go_to_the_earlier_quad_across_chunks_and_batches(monkeypatch, one_quad_each, method):
    # The same square three times, in three setup chunks or drawing batches: equal depths everywhere,
    # so the first drawn (quad 0) must own every pixel, as with the depth test "less".
    square = np.array([[[-1, -1, 0.2, 1], [1, -1, 0.2, 1], [1, 1, 0.2, 1], [-1, 1, 0.2, 1]]], dtype=float)
    clip = np.repeat(square, 3, axis=0)
    values = np.arange(3.0)[:, None, None] * np.ones((3, 4, 1))
    monkeypatch.setattr(render.raster, one_quad_each, 1)
    frame = rasterize_quads(clip, values, 8, 8, method)
    assert (frame.face == 0).all() and (frame.attrs == 0.0).all()


@pytest.mark.parametrize("method", METHODS)
def test_frame_does_not_depend_on_the_quad_batches(method, monkeypatch):
    # Batches are drawn one after the other into one frame (bounded memory for any quad count):
    # the grid seen twice, shifted back, overlaps itself, so later batches must lose and win by depth.
    clip, uv = perspective_grid()
    behind = clip.copy()
    behind[..., 2] += 0.05 * behind[..., 3]  # the same quads a little farther: hidden where they overlap
    clip, uv = np.concatenate([behind[::2], clip, behind[1::2]]), np.concatenate([uv[::2], uv, uv[1::2]])
    whole = rasterize_quads(clip, uv, 48, 40, method)
    monkeypatch.setattr(render.raster, "BATCH_QUADS", 7)
    batched = rasterize_quads(clip, uv, 48, 40, method)
    assert (whole.face >= 0).sum() > 500
    assert np.array_equal(whole.face, batched.face)
    assert np.array_equal(whole.attrs, batched.attrs, equal_nan=True)
    assert np.array_equal(whole.depth, batched.depth)
    assert whole.fragments == batched.fragments



def test_quads_stacked_past_the_fragment_budget_stop_with_a_clear_error(monkeypatch):
    # 50 squares over the whole 16 x 8 image: 50 x 128 = 6,400 fragments, 50 in every pixel. The
    # budget reads the setup's estimate, an upper bound: per triangle half the square's 128 pixels
    # plus its 16 columns, 80, spread over 8 rows: 8,000 in all, 1,000 a row.
    square = np.array([[[-1, -1, 0.2, 1], [1, -1, 0.2, 1], [1, 1, 0.2, 1], [-1, 1, 0.2, 1]]], dtype=float)
    clip, nothing = np.repeat(square, 50, axis=0), np.zeros((50, 4, 0))
    monkeypatch.setattr(render.raster, "MAX_FRAGMENTS", 7_999)
    with pytest.raises(ValueError, match=r"would draw about 8e\+03 fragments \(62.5 times the image's pixels, "
                                         r"up to 1e\+03 in one row\): over the render's budget of 8e\+03"):
        rasterize_quads(clip, nothing, 16, 8)
    monkeypatch.setattr(render.raster, "MAX_FRAGMENTS", 8_000)
    assert rasterize_quads(clip, nothing, 16, 8).fragments == 6_400
    monkeypatch.setattr(render.raster, "MAX_ROW_FRAGMENTS", 999)
    with pytest.raises(ValueError, match=r"up to 1e\+03 in one row"):
        rasterize_quads(clip, nothing, 16, 8)
