"""The visible reading's texture structures, built only where queries reach (issue 40's cost goal): the
decoded texels against a second reader (numpy over Pillow's own array), and the lazily reduced min/max and
step pyramids against brute force over every block, whatever order their bands are built in."""

from __future__ import annotations

import numpy as np
import pytest

from affinity.textures.filtering import BAND_TEXELS, RangePyramid


def block_extremes(image: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Per-channel minimum and maximum over every 2^k x 2^k block of ``image`` (H, W, D), a Python loop over
    blocks (a last partial block over the texels it has): the reference."""
    size = 1 << k
    height, width = -(-image.shape[0] // size), -(-image.shape[1] // size)
    low, high = (np.empty((height, width, image.shape[2]), dtype=image.dtype) for _ in range(2))
    for y in range(height):
        for x in range(width):
            block = image[y * size:(y + 1) * size, x * size:(x + 1) * size].reshape(-1, image.shape[2])
            low[y, x], high[y, x] = block.min(axis=0), block.max(axis=0)
    return low, high


@pytest.mark.parametrize("shape", [(37, 53, 3), (2 * BAND_TEXELS + 5, 3 * BAND_TEXELS + 1, 4), (1, 1, 1)])
def test_every_level_of_the_lazy_pyramid_is_its_blocks_extremes_whatever_the_band_order(shape):
    rng = np.random.default_rng(5)
    image = rng.integers(0, 256, shape, dtype=np.uint8)
    pyramid = RangePyramid(image)
    for k in reversed(range(pyramid.levels)):  # the top first: built straight from the texels
        bands = np.arange(len(pyramid._built[k]))
        pyramid._build(k, bands[1::2])  # every other band, then the rest
        pyramid._build(k, bands)
        low, high = block_extremes(image, k)
        np.testing.assert_array_equal(pyramid._levels[k][0], low)
        np.testing.assert_array_equal(pyramid._levels[k][1], high)


def test_a_query_reduces_only_the_bands_its_boxes_reach_and_answers_as_brute_force():
    """A box in the top rows builds the top bands only; the bounds it gets hold the box's extremes and are
    those of the four blocks that cover it (brute force)."""
    rng = np.random.default_rng(6)
    image = rng.integers(0, 256, (8 * BAND_TEXELS, 8 * BAND_TEXELS, 4), dtype=np.uint8)
    pyramid = RangePyramid(image, channels=3)
    low, high = pyramid.channel_bounds(np.array([5]), np.array([12]), np.array([2]), np.array([9]))
    built = [int(bands.sum()) for bands in pyramid._built[1:]]
    assert built == [0, 0, 1] + [0] * (pyramid.levels - 4)  # one band of level 3 answers an 8-texel box
    box = image[2:10, 5:13, :3].reshape(-1, 3)
    assert (low[0] <= box.min(axis=0)).all() and (high[0] >= box.max(axis=0)).all()
    cover = image[0:16, 0:16, :3].reshape(-1, 3)  # blocks (0, 0), (0, 1), (1, 0), (1, 1) of level 3
    np.testing.assert_array_equal(low[0], cover.min(axis=0))
    np.testing.assert_array_equal(high[0], cover.max(axis=0))


@pytest.mark.parametrize("mode", ["RGB", "RGBA", "L", "LA"])
def test_decoded_texels_are_the_images_and_the_step_pyramids_its_wrapped_steps(tmp_path, mode):
    from PIL import Image

    from affinity.textures.decode import decode

    rng = np.random.default_rng(7)
    channels = len(mode)
    array = rng.integers(0, 256, (45, 70, channels), dtype=np.uint8)
    Image.fromarray(array[..., 0] if channels == 1 else array, mode).save(tmp_path / f"{mode}.png")
    texture = decode(str(tmp_path / f"{mode}.png"))
    with Image.open(tmp_path / f"{mode}.png") as image:  # the second reader: Pillow's own array
        np.testing.assert_array_equal(texture.pixels, np.asarray(image).reshape(45, 70, channels))
    assert texture.texels.shape == (45, 70, 4) and texture.texels.flags.c_contiguous
    wide = array.astype(int)
    steps = [np.abs(np.roll(wide, -1, axis=axis) - wide).max(axis=2)[..., None] for axis in (1, 0)]
    for pyramid, step in zip(texture.slopes, steps):
        for k in range(pyramid.levels):
            pyramid._build(k, np.arange(len(pyramid._built[k])))
            np.testing.assert_array_equal(pyramid._levels[k][1], block_extremes(step.astype(np.uint8), k)[1])


@pytest.mark.parametrize("mode,interlace", [("RGB", False), ("RGBA", False), ("RGB", True)])
def test_a_png_decodes_in_place_into_the_texels_as_pillow_decodes_it(tmp_path, mode, interlace):
    """The PNG path that has Pillow decode straight into the texels' buffer (no copy out of Pillow) is taken
    on this Pillow and gives the written pixels, as Pillow's own ``np.asarray`` reads them, interlaced (Adam7)
    or not."""
    from PIL import Image, PngImagePlugin

    from affinity.textures.decode import _decoded_in_place

    array = np.random.default_rng(8).integers(0, 256, (33, 47, len(mode)), dtype=np.uint8)
    path = tmp_path / "t.png"
    if interlace:  # Pillow does not write Adam7: a minimal interlaced PNG by hand, Pillow's decoder reads it
        path.write_bytes(adam7_png(array))
    else:
        Image.fromarray(array, mode).save(path)
    with open(path, "rb") as file, PngImagePlugin.PngImageFile(file) as image:
        texels = _decoded_in_place(image)
    assert texels is not None
    np.testing.assert_array_equal(texels[..., :len(mode)], array)
    with Image.open(path) as image:
        np.testing.assert_array_equal(texels[..., :len(mode)], np.asarray(image))


def adam7_png(array: np.ndarray) -> bytes:
    """An 8-bit RGB PNG of ``array`` (H, W, 3) with Adam7 interlacing (filter 0 on every row)."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    height, width = array.shape[:2]
    passes = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
    raw = b"".join(b"\0" + row.tobytes() for x0, y0, dx, dy in passes
                   for row in array[y0::dy, x0::dx] if row.size)
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 1)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
