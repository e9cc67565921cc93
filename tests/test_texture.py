import numpy as np
import pytest

from affinity.draw.texture import TextureError, checker, load_image, sample_bilinear


def test_sampling_at_texel_centres_returns_the_texels():
    image = np.random.default_rng(1).random((4, 6, 3))
    rows, cols = np.meshgrid(np.arange(4), np.arange(6), indexing="ij")
    uv = np.stack([(cols + 0.5) / 6, 1 - (rows + 0.5) / 4], axis=-1).reshape(-1, 2)
    np.testing.assert_allclose(sample_bilinear(image, uv), image.reshape(-1, 3), atol=1e-6)


def test_sampling_between_texels_averages_and_wraps():
    image = np.zeros((2, 2, 1))
    image[0, 0] = 1.0  # top-left texel
    # The corner uv = (0, 1) is the top-left image corner: halfway between the four
    # texels around it once the texture repeats.
    np.testing.assert_allclose(sample_bilinear(image, np.array([[0.0, 1.0], [1.0, 0.0], [2.0, -1.0]])), 0.25)
    # Midway between texel centres (0, 0) and (0, 1) of the top row.
    np.testing.assert_allclose(sample_bilinear(image, np.array([[0.5, 0.75]])), 0.5)


@pytest.mark.parametrize("channels", [1, 3, 4])
def test_packed_sampling_is_bilinear_filtering_of_the_texels(channels):
    """The lint's packed sampler: texel centres give the texels, midpoints the mean of their neighbours,
    repeating past the edges (closed forms on random uint8 texels)."""
    from affinity.textures.filtering import PackedTexture

    pixels = np.random.default_rng(2).integers(0, 256, (5, 7, channels), dtype=np.uint8)
    packed = PackedTexture(pixels)
    rows, cols = np.meshgrid(np.arange(5), np.arange(7), indexing="ij")
    centres = np.stack([(cols + 0.5) / 7, 1 - (rows + 0.5) / 5], axis=-1).reshape(-1, 2)
    np.testing.assert_allclose(packed.sample(centres), pixels.reshape(-1, channels), atol=1e-4)
    np.testing.assert_allclose(packed.sample(centres + [1.0, -2.0]), pixels.reshape(-1, channels), atol=1e-4)
    between = np.array([[1.0 / 7, 1 - 0.5 / 5]])  # between the first two texels of the top row
    np.testing.assert_allclose(packed.sample(between), (pixels[0, :1].astype(float) + pixels[0, 1:2]) / 2,
                               atol=1e-4)


def test_the_range_pyramid_holds_every_box_and_is_exact_on_its_blocks():
    """Brute force over random boxes of an odd-sized image: the bounds hold the box's true extremes, and
    equal them on a box that is one of the pyramid's blocks."""
    from affinity.textures.filtering import RangePyramid

    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (37, 53, 3), dtype=np.uint8)
    pyramid = RangePyramid(image)
    x0, y0 = rng.integers(0, 53, 200), rng.integers(0, 37, 200)
    x1, y1 = np.minimum(x0 + rng.integers(0, 40, 200), 52), np.minimum(y0 + rng.integers(0, 30, 200), 36)
    low, high = pyramid.channel_bounds(x0, x1, y0, y1)
    for k in range(200):
        box = image[y0[k]:y1[k] + 1, x0[k]:x1[k] + 1].reshape(-1, 3)
        assert (low[k] <= box.min(axis=0)).all() and (high[k] >= box.max(axis=0)).all()
    low, high = pyramid.channel_bounds(np.array([8]), np.array([15]), np.array([16]), np.array([23]))
    block = image[16:24, 8:16].reshape(-1, 3)
    np.testing.assert_array_equal(low[0], block.min(axis=0))
    np.testing.assert_array_equal(high[0], block.max(axis=0))


def test_checker_alternates():
    image = checker(64, checks=4)
    assert image.shape == (64, 64, 3)
    a, b = image[8, 8], image[8, 24]
    assert not np.allclose(a, b) and np.allclose(image[24, 24], a)


def test_unreadable_texture_is_a_texture_error(tmp_path):
    with pytest.raises(TextureError, match="no such"):
        load_image(str(tmp_path / "missing.png"))
    junk = tmp_path / "junk.png"
    junk.write_bytes(b"not an image")
    with pytest.raises(TextureError, match="not a readable image"):
        load_image(str(junk))
