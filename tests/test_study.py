"""The study's metrics on hand-made images with known values, its timing harness, and the
paper's trapezoid (Bloomenthal Fig. 3) measured end to end."""

import math

import numpy as np
import pytest

from affinity.study.metrics import crease, error_summary, psnr, ssim, texels_per_pixel
from affinity.study.sweep import mark_pareto
from affinity.study.timing import machine_facts, time_interleaved
from render import rasterize_quads

# ---------------------------------------------------------------- error, PSNR, SSIM, density


def pixel_grid(width, height):
    """Column and row index of every pixel, (H, W) float each."""
    return np.meshgrid(np.arange(width, dtype=float), np.arange(height, dtype=float))


def test_error_summary_of_a_known_field():
    error = np.arange(1.0, 101.0)  # 1 .. 100
    summary = error_summary(np.random.default_rng(0).permutation(error))
    assert summary["rms"] == pytest.approx(math.sqrt(100 * 101 * 201 / 6 / 100), rel=1e-15)
    assert summary["p99"] == pytest.approx(99.01, rel=1e-12)  # linear interpolation at rank 98.01
    assert summary["max"] == 100.0
    assert all(math.isnan(v) for v in error_summary(np.zeros(0)).values())


def test_psnr_of_a_constant_offset():
    rng = np.random.default_rng(1)
    image = rng.uniform(0.2, 0.8, size=(20, 30, 3))
    mask = np.ones((20, 30), dtype=bool)
    assert psnr(image + 0.1, image, mask) == pytest.approx(20.0, abs=1e-9)  # 10 log10(1 / 0.1^2)
    assert psnr(image + 0.01, image, mask) == pytest.approx(40.0, abs=1e-9)
    assert psnr(image, image, mask) == math.inf
    mask[:, 15:] = False  # only the masked pixels count
    other = image.copy()
    other[:, 15:] += 0.5
    assert psnr(other, image, mask) == math.inf


def test_ssim_of_identical_images_is_one_and_of_constants_has_its_closed_form():
    rng = np.random.default_rng(2)
    image = rng.uniform(size=(24, 32, 3))
    mask = np.ones((24, 32), dtype=bool)
    assert ssim(image, image, mask) == pytest.approx(1.0, abs=1e-12)
    # Constant images a and a + c: no variance, no covariance, so SSIM is the luminance
    # term (2 a (a + c) + C1) / (a^2 + (a + c)^2 + C1) with C1 = (0.01 * 1)^2.
    a, c, c1 = 0.4, 0.2, 0.01**2
    flat = np.full((24, 32, 3), a)
    expected = (2 * a * (a + c) + c1) / (a * a + (a + c) ** 2 + c1)
    assert ssim(flat + c, flat, mask) == pytest.approx(expected, rel=1e-12)
    noisy = np.clip(image + rng.normal(scale=0.2, size=image.shape), 0, 1)
    assert ssim(noisy, image, mask) == pytest.approx(ssim(image, noisy, mask), rel=1e-12)  # symmetric
    assert 0 < ssim(noisy, image, mask) < 0.9


def test_texels_per_pixel_of_a_linear_uv_field():
    col, row = pixel_grid(7, 5)
    uv = np.stack([0.01 * col + 0.002 * row, -0.004 * col + 0.02 * row], axis=-1)
    face = np.zeros((5, 7), dtype=np.int64)
    face[:, 4:] = 1  # a second quad: differences never cross into it
    face[0, 0] = -1
    uv[face == 1] += 7.0
    density = texels_per_pixel(uv, face, (512, 256))
    expected = math.sqrt(abs((0.01 * 512) * (0.02 * 256) - (0.002 * 256) * (-0.004 * 512)))
    assert np.allclose(density[face >= 0], expected, rtol=1e-12)
    assert np.isnan(density[0, 0])
    face[:, 6] = 2  # a one-pixel-wide quad has no neighbour along its rows
    assert np.isnan(texels_per_pixel(uv, face, 512)[:, 6]).all()


# ---------------------------------------------------------------- crease


def one_quad(width, height):
    """A convex quad in NDC (w = 1) filling most of the image, and the rasterizer's face map."""
    corners = np.array([[-0.9, -0.8], [0.85, -0.9], [0.9, 0.95], [-0.8, 0.9]])
    clip = np.concatenate([corners, np.zeros((4, 1)), np.ones((4, 1))], axis=1)[None]
    return clip, rasterize_quads(clip, np.zeros((1, 4, 0)), width, height, "split").face


def signed_distance_to_diagonal(clip, width, height):
    """Distance (H, W) in pixels of every pixel centre from the line through corners 0 and 2."""
    col, row = pixel_grid(width, height)
    x = (clip[0, [0, 2], 0] + 1) * width / 2 - 0.5
    y = (1 - clip[0, [0, 2], 1]) * height / 2 - 0.5
    dx, dy = x[1] - x[0], y[1] - y[0]
    return ((col - x[0]) * dy - (row - y[0]) * dx) / math.hypot(dx, dy)


def test_crease_of_a_known_piecewise_linear_field():
    width, height = 60, 50
    clip, face = one_quad(width, height)
    col, row = pixel_grid(width, height)
    d = signed_distance_to_diagonal(clip, width, height)
    jump = np.array([0.03, -0.5])  # per pixel, for two channels
    smooth = np.stack([0.2 + 0.01 * col - 0.02 * row, 3.0 + 1e-3 * col * row - 2e-3 * row**2], axis=-1)
    for field, expected in ((smooth + np.maximum(d, 0)[..., None] * jump, jump),
                            (smooth + np.maximum(-d, 0)[..., None] * jump, jump),  # the other side: same size
                            (smooth, np.zeros(2))):
        got, pixels = crease(field, face, clip)
        assert pixels[0] == (face == 0).sum()
        assert np.abs(np.abs(got[0]) - np.abs(expected)).max() < 1e-9


def test_crease_is_nan_for_quads_too_small_to_fit():
    clip, face = one_quad(8, 6)
    got, _ = crease(np.zeros((6, 8, 1)), face, clip)
    assert np.isnan(got).all()


# ---------------------------------------------------------------- timing and the Pareto front


def test_timing_warms_up_and_interleaves_the_calls():
    order = []
    calls = [lambda: order.append("a") or "A", lambda: order.append("b") or "B"]
    timings = time_interleaved(calls, repeat=3, warmup=1)
    assert order == ["a", "b"] * 4
    assert [t.result for t in timings] == ["A", "B"]
    for t in timings:
        assert t.seconds.shape == (3,) and t.low <= t.median <= t.high
    with pytest.raises(ValueError):
        time_interleaved(calls, repeat=0)


def test_machine_facts_name_the_cpu_cores_and_numpy():
    facts = machine_facts()
    assert facts["numpy"] == np.__version__
    assert int(facts["logical cores"]) >= 1 and facts["cpu"]


def test_pareto_front_keeps_only_unbeaten_candidates():
    rows = [{"method": m, "seconds": s, "err_rms": e} for m, s, e in [
        ("split", 1.0, 10.0), ("mvc", 2.0, 1.0), ("bilinear", 3.0, 1.0), ("projective", 1.0, 12.0),
        ("hybrid", 1.5, 1.0), ("exact", 4.0, 0.0), ("split-13", 0.5, 0.5)]]
    mark_pareto(rows)
    assert [row["method"] for row in rows if row["pareto"]] == ["split", "hybrid"]


# ---------------------------------------------------------------- the paper's trapezoid


@pytest.fixture(scope="module")
def trapezoid_rows():
    from affinity.scenes import study_scenes
    from affinity.study.sweep import StudySettings, prepare, study_scene

    settings = StudySettings(width=160, height=120, repeat=1, warmup=0, tolerances=(0.5,))
    case = next(case for case in study_scenes() if case.name == "trapezoid front")
    rows = study_scene(prepare(case, settings), settings)
    return {row["method"]: row for row in rows if row["method"] != "hybrid" or row["route"] == "view"}


def test_on_the_trapezoid_the_split_has_the_crease_and_the_error(trapezoid_rows):
    rows = trapezoid_rows
    split = rows["split"]
    for method in ("mvc", "bilinear", "projective"):
        assert split["crease_max"] > 10 * rows[method]["crease_max"], method
    assert split["crease_max"] > 3  # texels per pixel: the gradient jumps across the diagonal
    assert split["err_rms"] > 10 * rows["mvc"]["err_rms"]
    # Seen straight on, every corner has the same w: bilinear is exact.
    assert rows["bilinear"]["err_rms"] < 1e-6
    # The split's error against exact peaks at the closed form of the trapezoid with side ratio r = 1/2
    # carrying the unit square: (1 - r) / (1 + sqrt r)^2 of the uv width, in texels of 1024; the pixel
    # centres sample just below that supremum.
    sup = 1024 * 0.5 / (1 + math.sqrt(0.5)) ** 2  # 175.7 texels
    assert 0.97 * sup < split["err_max"] <= sup * (1 + 1e-9)
    # Projective has no crease but maps the square texture as a square seen in
    # perspective: at the diagonals' crossing, a sixth of the height above the
    # trapezoid's centre, it puts the texture's centre (v = 1/2 against exact's 2/3).
    # On this trapezoid it departs from exact more than the split does.
    assert rows["projective"]["err_max"] > 1024 / 6 * 0.95
    assert rows["projective"]["err_rms"] > split["err_rms"]
    assert rows["hybrid"]["to_mvc"] == 1.0 and rows["hybrid"]["err_rms"] == rows["mvc"]["err_rms"]
    assert math.isnan(split["diagonal_rms"])  # only split-13 has it
    assert rows["split-13"]["diagonal_rms"] > 10


# ---------------------------------------------------------------- what is shown: the registries' data


@pytest.fixture(scope="module")
def color_rows():
    """Bloomenthal Fig. 10 (two unit squares: corner colours blue, red, green, black on the left, an affine set
    on the right) seen straight on, every configuration, with the lint route swept at two thresholds."""
    from affinity.scenes import SCENES
    from affinity.study.sweep import StudySettings, prepare, study_scene

    settings = StudySettings(width=160, height=80, repeat=1, warmup=0, misplacement_thresholds=(2.0, 4.0))
    case = next(case for case in SCENES if case.name == "color squares")  # a demo scene, not in the study
    return study_scene(prepare(case, settings), settings)


def test_study_errors_are_in_the_unit_the_attribute_registry_gives(trapezoid_rows, color_rows):
    from affinity.attributes import ATTRIBUTES
    from affinity.lint import scored_codes
    from affinity.rules import RULES

    for field, rows in (("texcoords", trapezoid_rows.values()), ("colors", color_rows)):
        unit = ATTRIBUTES[field].unit
        codes = scored_codes(attribute=ATTRIBUTES[field].name)
        assert {row["unit"] for row in rows} == {unit} == {RULES[code].unit for code in codes}
    # The split's colour error against exact peaks at the left square's centre: bilinear minus the split is
    # R t (1 - s), R = c0 - c1 + c2 - c3 = (-1, 1, 1), so |R| / 4 = sqrt(3) / 4 of full scale, in 1/255 steps.
    split = next(row for row in color_rows if row["method"] == "split")
    sup = 255 * math.sqrt(3) / 4  # 110.4
    assert 0.95 * sup < split["err_max"] <= sup * (1 + 1e-9)
    # The barycentric reading is the uv rule's only (Rule.readings): colours route by the error reading alone.
    assert {row["route"] for row in color_rows} == {"", "lint error"}


def test_the_headline_setting_and_its_words_follow_the_registries(color_rows, monkeypatch):
    from dataclasses import replace

    from affinity.attributes import ATTRIBUTES
    from affinity.lint import scored_codes
    from affinity.rules import RULES
    from affinity.study.tables import error_label, headline_hybrid, summary_markdown

    (code,) = scored_codes(attribute="colour")
    scene = color_rows[0]["scene"]
    assert headline_hybrid(color_rows, scene)["setting"] == RULES[code].default_threshold == 2.0
    monkeypatch.setitem(RULES, code, replace(RULES[code], default_threshold=4.0))
    monkeypatch.setitem(ATTRIBUTES, "colors", replace(ATTRIBUTES["colors"], label="tint"))
    assert headline_hybrid(color_rows, scene)["setting"] == 4.0
    assert error_label(color_rows[0]["unit"]) == "RMS tint error (1/255)"  # the charts' axis
    summary = summary_markdown(color_rows, {"cpu": "test"}, ["# study"])
    assert f"0.5 px tolerance, by view; tint by lint: the {code} threshold, 4/255)" in summary
    split = next(row for row in color_rows if row["method"] == "split")
    assert f"| {split['err_rms']:.3g}/255 |" in summary  # a number in 1/255 steps reads as a fraction
