"""One column, one unit (design.md, Clarifications "One findings table"; issue 51).

A Q101 finding read through a texture has ``value`` = C (1/255 steps) and the split's shift (texels) in its own
column; every consumer that needs the shift or a rank reads the right column. The scene is the issue's: a 6 x 6
grid whose uv is sheared by a bilinear term, under a 256 px checker, whose shift has a closed form
(:mod:`helpers.sheared_grid`).
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.sheared_grid import SHIFT, SIDE, TEXTURE, grid_obj


def checked(path, **settings):
    from affinity.pipeline.check import load_and_check
    from affinity.settings import Settings

    report, _ = load_and_check(str(path), Settings(texture_size=TEXTURE, **settings))
    assert report.error is None, report.error
    return report


def q101(report):
    return next(h for h in report.hits if h.code == "Q101")


def test_the_shift_column_is_the_closed_form_shift_in_texels_where_value_is_c(tmp_path):
    hits = q101(checked(grid_obj(tmp_path)))
    assert len(hits) == SIDE * SIDE
    assert hits.visible is not None and hits.visible.read().all()
    np.testing.assert_allclose(hits.shifts, SHIFT, rtol=1e-9)
    assert set(hits.units()) == {"1/255"}
    # C is read through the checker: up to a whole step of it, far from the shift's number of texels
    assert (hits.values > 0).all() and (hits.values <= 255).all() and hits.values.max() > 100
    np.testing.assert_array_equal(hits.thresholds(), 2.0)  # visible-warning, C's own threshold


def test_the_shift_column_does_not_depend_on_the_texture_being_read(tmp_path):
    """Without a texture the value is the shift itself; with one, the shift column keeps it."""
    plain, textured = tmp_path / "plain", tmp_path / "textured"
    plain.mkdir(), textured.mkdir()
    without = q101(checked(grid_obj(plain, material=None)))
    with_texture = q101(checked(grid_obj(textured)))
    assert without.visible is None and set(without.units()) == {"texels"}
    np.testing.assert_array_equal(without.shifts, without.values)
    np.testing.assert_allclose(without.values, SHIFT, rtol=1e-9)
    np.testing.assert_array_equal(with_texture.faces, without.faces)
    np.testing.assert_allclose(with_texture.shifts, without.shifts, rtol=1e-12)


def test_json_value_is_c_and_shift_is_texels_per_row(tmp_path):
    from affinity.output import select

    report = checked(grid_obj(tmp_path))
    rows = [f for f in select(report).findings() if f.code == "Q101"]
    assert {f.unit for f in rows} == {"1/255"} and {f.threshold for f in rows} == {2.0}
    np.testing.assert_allclose([f.shift for f in rows], SHIFT, rtol=1e-9)
    assert all(f.value != pytest.approx(f.shift) for f in rows)


def test_findings_in_two_units_rank_by_their_own_thresholds(tmp_path):
    """Half the quads bind the checker (C in 1/255), half a material without a map (the shift in texels): at one
    level, each ranks by how far it is beyond its own threshold, never by comparing C with texels."""
    from affinity.output import badness, worst_first

    hits = q101(checked(grid_obj(tmp_path, split_materials=True)))
    read = hits.visible.read()
    assert read.any() and (~read).any()
    np.testing.assert_array_equal(hits.units()[read], "1/255")
    np.testing.assert_array_equal(hits.units()[~read], "texels")
    np.testing.assert_allclose(hits.shifts, SHIFT, rtol=1e-9)  # every row, read or not
    ratios = np.where(read, hits.values / 2.0, SHIFT / 0.5)  # C / visible-warning, shift / Q101's threshold
    np.testing.assert_allclose(badness(hits), -ratios, rtol=1e-12)
    order = worst_first(hits)
    ranks = hits.level_ranks()[order]
    assert (np.diff(ranks) >= 0).all()
    for rank in np.unique(ranks):
        within = ratios[order[ranks == rank]]
        assert (np.diff(within) <= 1e-12).all(), "within a level, the larger ratio first"


def test_the_worst_finding_and_place_are_the_furthest_beyond_their_own_threshold(tmp_path):
    """A faint checker (grey levels 0 and 4): C is at most 4/255, 2x visible-warning at most, while the plain half's
    shift is 2.13x Q101's threshold. Both are warnings; the worst is a plain quad, though its value (1.07 texels)
    is the smaller number."""
    from affinity.loaders import load
    from affinity.output import worst_first
    from affinity.report.places import places_of

    path = grid_obj(tmp_path, split_materials=True, contrast=4)
    hits = q101(checked(path))
    read = hits.visible.read()
    assert read.any() and (hits.values[read] <= 4.0 + 1e-9).all() and (hits.values[read] > SHIFT).any()
    assert set(hits.levels()[(hits.values >= 2.0) | ~read]) == {"warning"}
    worst = worst_first(hits)[0]
    assert not read[worst]
    [place] = places_of(load(str(path)), hits, limit=SIDE * SIDE)  # one group: the grid is connected
    assert place.worst in hits.faces[~read] and place.beyond == pytest.approx(SHIFT / 0.5)
