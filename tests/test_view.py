"""The 3-D view (pyvista) draws each attribute's scores as the attribute registry says: colour map, legend, unit.

Issue 39: what is shown and how is registry data. The truth for the colours is matplotlib's colour map of
the registry's name; for the unit, the rule registry's unit of the scores' reading.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from affinity.attributes import ATTRIBUTES  # noqa: E402
from affinity.lint import quad_scores, scored_codes  # noqa: E402
from affinity.loaders import load  # noqa: E402
from affinity.rules import RULES  # noqa: E402
from affinity.settings import MEASURES, Settings  # noqa: E402
from affinity.view import build_scene  # noqa: E402

#: One trapezoid (side ratio 1/2) carrying each attribute at its corners: uv, vertex colours, normals.
TRAPEZOID = """v 0 0 0 1 0 0
v 4 0 0 0 1 0
v 3 1 0 0 0 1
v 1 1 0 0 0 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
vn 1 0 1
vn 0 1 1
vn -1 0 1
f 1/1/1 2/2/2 3/3/3 4/4/4
"""


@pytest.fixture(scope="module")
def trapezoid(tmp_path_factory):
    path = tmp_path_factory.mktemp("view") / "trapezoid.obj"
    path.write_text(TRAPEZOID)
    return load(str(path))


def drawn(mesh, scores):
    """The colour bar titles of the scene and the colour its lowest score gets, (4,) float RGBA."""
    plotter = pv.Plotter(off_screen=True)
    try:
        build_scene(plotter, mesh, scores)
        (surface, *_) = plotter.renderer.actors.values()
        table = surface.mapper.lookup_table
        return list(plotter.scalar_bars.keys()), np.asarray(table.map_value(table.scalar_range[0]))
    finally:
        plotter.close()


def test_every_scored_attribute_is_drawn_with_its_registered_colour_map_legend_and_unit(trapezoid):
    from matplotlib import colormaps

    codes = scored_codes(trapezoid)
    assert {RULES[code].attribute for code in codes} == set(ATTRIBUTES)  # the fixture carries every attribute
    for code in codes:
        attribute = ATTRIBUTES[RULES[code].attribute]
        for measure in MEASURES:
            scores = quad_scores(trapezoid, Settings(measure=measure), code)
            titles, lowest = drawn(trapezoid, scores)
            unit = RULES[code].unit_for(measure)
            assert titles == [f"{attribute.label} score ({unit})\n"], (code, measure)
            np.testing.assert_allclose(lowest, colormaps[attribute.colormap](0.0), atol=1 / 255)
        assert RULES[code].unit == attribute.unit  # the rule measures in its attribute's unit


def test_a_registry_entry_changed_in_a_test_is_drawn_without_code_changes(trapezoid, monkeypatch):
    from matplotlib import colormaps

    tint = replace(ATTRIBUTES["colors"], label="tint", colormap="magma")
    monkeypatch.setitem(ATTRIBUTES, "colors", tint)
    (code,) = [code for code in scored_codes(trapezoid) if RULES[code].attribute == "colors"]
    titles, lowest = drawn(trapezoid, quad_scores(trapezoid, Settings(), code))
    assert titles == [f"tint score ({tint.unit})\n"]
    np.testing.assert_allclose(lowest, colormaps["magma"](0.0), atol=1 / 255)
    assert not np.allclose(lowest, colormaps["viridis"](0.0), atol=1 / 255)
