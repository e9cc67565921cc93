"""findings.settle: lint's hits in, settled hits out, lint's own left as they were."""

from __future__ import annotations

import numpy as np
from helpers.quads import UNIT_UV, hits, quad_obj, trapezoid

from affinity.findings import settle
from affinity.lint import lint_mesh
from affinity.loaders import load
from affinity.settings import Settings


def test_settle_returns_new_hits_and_leaves_its_input_as_it_was():
    """Issue 39: settle set the level, unit and visibility threshold on the hits it was given."""
    found = [hits("Q101", [0, 1, 2], [5, 6, 7], [3.0, 0.7, 9.0]), hits("Q204", [1], [6], [0.5], 0.0)]
    settings = Settings(levels={"Q204": "info"}, thresholds={"Q101": 0.6})
    settled = settle(found, settings, ["body"], inline=[(["Q101"], np.array([1]))])
    # lint's records: untouched
    assert [(h.level, h.unit, h.error_above) for h in found] == [(None, None, None)] * 2
    assert found[0].faces.tolist() == [0, 1, 2]
    # the settled ones: Q101 read in texels with its 2-texel visibility threshold (design.md), face 1 silenced
    # inline; Q204 at the level [levels] gives it, with no visibility threshold (the level is fixed)
    q101, q204 = settled
    assert (q101.level, q101.unit, q101.error_above) == ("warning", "texels", 2.0)
    assert q101.faces.tolist() == [0, 2] and q101.levels().tolist() == ["error", "error"]
    assert (q204.level, q204.error_above) == ("info", None) and q204.levels().tolist() == ["info"]


def test_the_settled_hits_of_a_mesh_are_a_function_of_its_lint(tmp_path):
    """Settling the same lint twice with different settings gives each settings' levels: the first
    settle leaves nothing behind for the second to see."""
    path = tmp_path / "trapezoid.obj"
    path.write_text(quad_obj([(trapezoid(0.5), UNIT_UV)]))  # Q101 175.7 texels at 1024 (the rule's page)
    linted = lint_mesh(load(path), Settings(select=["Q101"]), visible=False)
    fixed = settle(linted, Settings(levels={"Q101": "info"}), [""])
    free = settle(linted, Settings(), [""])
    assert fixed[0].levels().tolist() == ["info"]
    assert free[0].levels().tolist() == ["error"]  # above the 2-texel visibility threshold
