"""Texture lookups are filtered by each pixel's footprint (trilinear mip-mapping): a minified pattern shows its
mean, not moire. Against closed forms (block means, the texture's mean) and a real per-face-uv mesh's spectrum."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.corpus import SHARED_MESHES

from affinity.draw.texture import LOD_BIAS, checker, mip_levels, sample_bilinear, sample_mipmapped
from affinity.mesh import mesh_from_polygons

#: Cycles per pixel above which a picture's energy is aliasing: the upper half of the band up to Nyquist (0.5).
HIGH_BAND = 0.25


def test_each_mip_level_is_the_mean_of_its_block_of_base_texels():
    rng = np.random.default_rng(1)
    image = rng.random((32, 16, 3))
    levels = mip_levels(image)
    assert [level.shape[:2] for level in levels] == [(32, 16), (16, 8), (8, 4), (4, 2), (2, 1), (1, 1)]
    for k, level in enumerate(levels[:5]):
        side = 2**k
        blocks = image.reshape(32 // side, side, 16 // side, side, 3).mean(axis=(1, 3))
        np.testing.assert_allclose(level, blocks, atol=1e-6)
    np.testing.assert_allclose(levels[-1][0, 0], image.mean(axis=(0, 1)), atol=1e-6)


def test_a_magnified_texture_is_sampled_as_bilinear_filtering_does():
    rng = np.random.default_rng(2)
    image = rng.random((64, 64, 3)).astype(np.float32)
    uv = rng.random((500, 2))
    footprint = np.full((500, 2), 2.0**-LOD_BIAS / 64 * 0.99)  # just under the bias: level 0
    footprint[::7] = np.nan  # unknown: level 0 as well
    np.testing.assert_allclose(sample_mipmapped(image, uv, footprint), sample_bilinear(image, uv), atol=1e-6)


def test_a_finely_tiled_checker_on_a_facing_square_renders_as_the_checker_s_mean():
    """A square filling most of a 160-pixel picture, its uv running over 8 tiles of the 32-check texture: 256
    checks across about 130 pixels, half a pixel each. Box-filtered by the pixel, that is the texture's mean
    (a closed form); base-level sampling would pick checks at random (moire)."""
    from affinity import RenderOptions, render_mesh

    square = mesh_from_polygons("tiled", [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2, 3]],
                                texcoords=np.array([[0, 0], [8, 0], [8, 8], [0, 8]], dtype=float))
    drawn = render_mesh(square, RenderOptions(method="split", show="uv", width=160, height=160,
                                              camera=((0.0, 0.0, 4.5), (0.0, 0.0, 0.0), 30.0), up="y",
                                              texture=checker()))
    inside = drawn.frame.face >= 0
    assert inside.sum() > 100 * 100
    mean = checker().reshape(-1, 3).mean(axis=0)
    assert np.abs(drawn.image[inside] - mean).max() < 3 / 255
    aliased = sample_bilinear(checker(), drawn.frame.attrs[inside])
    assert np.abs(aliased - mean).max() > 0.3  # what the test guards against


def high_band_rms(image: np.ndarray, covered: np.ndarray) -> float:
    """The root mean square, in 1/255 per covered pixel, of the luminance's spectrum above ``HIGH_BAND``
    cycles per pixel (the covered pixels less their mean; the background at 0)."""
    luminance = image.mean(axis=2) * covered
    luminance = luminance - luminance[covered].mean() * covered
    power = np.abs(np.fft.fft2(luminance)) ** 2
    frequency = np.hypot(np.fft.fftfreq(image.shape[0])[:, None], np.fft.fftfreq(image.shape[1])[None])
    return float(255 * np.sqrt(power[frequency > HIGH_BAND].sum() / power.size / covered.sum()))


def test_the_overview_of_the_per_face_uv_car_has_no_energy_near_nyquist():
    """The car maps every quad onto the whole checker: in the report's overview render a quad is a few pixels,
    a check a fraction of one. Filtered, the energy in the upper half of the band is under 3/255 (measured
    0.98); the same frame's uv sampled at the base level (moire) has 55/255 there."""
    car = SHARED_MESHES / "osd_catmark_car.obj"
    if not car.is_file():
        pytest.skip("../shared/meshes is absent")
    from affinity import RenderOptions, render_mesh

    drawn = render_mesh(str(car), RenderOptions(method="split", show="uv", width=480, height=360))
    covered = drawn.frame.face >= 0
    assert high_band_rms(drawn.image, covered) < 3.0
    moire = np.ones_like(drawn.image)
    moire[covered] = sample_bilinear(checker(), drawn.frame.attrs[covered])
    assert high_band_rms(moire, covered) > 20.0
