"""The contracts between lint and the rules' checks (issue 39): one signature, checks that measure and
never read their own threshold."""

from __future__ import annotations

import inspect

import numpy as np
import pytest

from affinity.attributes import ATTRIBUTES
from affinity.lint import CornerTables, QuadBatch, WholeMesh, lint_mesh
from affinity.mesh import Mesh
from affinity.rules import RULES, Measured
from affinity.settings import Settings


def quads_with_normals(corners: np.ndarray, normals: np.ndarray) -> Mesh:
    """Separate quads, (Q, 4, 3) corners and (Q, 4, 3) corner normals (scaled to unit length by lint)."""
    q = len(corners)
    return Mesh(path="quads.obj", positions=corners.reshape(-1, 3), face_start=np.arange(0, 4 * q + 1, 4),
                corner_vertex=np.arange(4 * q), normals=normals.reshape(-1, 3), corner_normal=np.arange(4 * q),
                face_line=np.arange(1, q + 1))


def batch_of(mesh: Mesh, settings: Settings) -> QuadBatch:
    """Every quad of ``mesh`` as one batch, the context lint gives a quad rule's check."""
    tables = CornerTables(mesh)
    for name in ("positions", *ATTRIBUTES):
        tables.prepare(name)
    faces = np.flatnonzero(mesh.face_sizes == 4)
    return QuadBatch(tables, settings, faces, mesh.face_start[faces] + np.arange(4)[:, None], (1024, 1024))


@pytest.fixture
def leaning_normals() -> Mesh:
    """Unit squares whose corner normals lean out at random, by up to about 40 degrees."""
    rng = np.random.default_rng(39)
    q = 300
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    corners = square + 3 * np.arange(q)[:, None, None] * np.array([1.0, 0, 0])
    normals = np.concatenate([rng.uniform(-0.8, 0.8, (q, 4, 2)), np.ones((q, 4, 1))], axis=2)
    return quads_with_normals(corners, normals)


def test_every_check_has_one_signature_and_returns_measured(leaning_normals):
    """One parameter, the context; a Measured back, for quad and mesh rules alike."""
    for code, rule in RULES.items():
        assert list(inspect.signature(rule.check).parameters) in (["quads"], ["context"]), code
    batch = batch_of(leaning_normals, Settings())
    for rule in RULES.values():
        context = batch if rule.scope == "quad" else WholeMesh(leaning_normals, Settings())
        measured = rule.check(context)
        assert isinstance(measured, Measured), rule.code
        assert len(np.arange(len(context.faces))[measured.rows]) == len(measured.values), rule.code


def test_q103_measures_every_quad_whatever_its_threshold(leaning_normals):
    """Issue 39: Q103's check read its threshold and skipped the quads below it (scores came from
    linting at -inf). The check is a pure measure: the same values at any threshold."""
    check = RULES["Q103"].check
    readings = [check(batch_of(leaning_normals, Settings(thresholds={"Q103": t}))) for t in (0.0, 2.0, 45.0, 89.0)]
    for measured in readings:
        assert np.arange(300)[measured.rows].tolist() == list(range(300))
        np.testing.assert_array_equal(measured.values, readings[0].values)
    # lint compares them with the threshold: what it keeps at 2 degrees is the values above 2
    [hits] = lint_mesh(leaning_normals, Settings(select=["Q103"], thresholds={"Q103": 2.0}), visible=False)
    above = readings[0].values > 2.0
    assert hits.faces.tolist() == np.flatnonzero(above).tolist()
    np.testing.assert_array_equal(hits.values, readings[0].values[above])


def test_q103_is_the_worst_turn_of_the_split_normal_found_by_dense_sampling(leaning_normals):
    """Independent truth: on a unit square the split along 0-2 (or 1-3) and the bilinear normal field
    differ by E(s, t); Q103 is atan2(max |E|, |mean corner normal|) over the worse diagonal, in degrees."""
    measured = RULES["Q103"].check(batch_of(leaning_normals, Settings()))
    n = leaning_normals.normals.reshape(-1, 4, 3)[:8]
    n = n / np.linalg.norm(n, axis=2, keepdims=True)
    s, t = np.meshgrid(np.linspace(0, 1, 801), np.linspace(0, 1, 801))
    s, t = s.ravel()[:, None], t.ravel()[:, None]
    for q in range(8):
        n0, n1, n2, n3 = n[q]
        bilinear = (1 - s) * (1 - t) * n0 + s * (1 - t) * n1 + s * t * n2 + (1 - s) * t * n3
        # along 0-2: triangle (0, 1, 2) where s >= t, (0, 2, 3) where s < t; along 1-3: (0, 1, 3) where s + t <= 1
        split02 = np.where(s >= t, n0 + s * (n1 - n0) + t * (n2 - n1), n0 + s * (n2 - n3) + t * (n3 - n0))
        split13 = np.where(s + t <= 1, n0 + s * (n1 - n0) + t * (n3 - n0),
                           n2 + (1 - s) * (n3 - n2) + (1 - t) * (n1 - n2))
        worst = max(np.linalg.norm(split02 - bilinear, axis=1).max(), np.linalg.norm(split13 - bilinear, axis=1).max())
        expected = np.degrees(np.arctan2(worst, np.linalg.norm(n[q].mean(axis=0))))
        assert measured.values[q] == pytest.approx(expected, rel=1e-5, abs=1e-9)


@pytest.fixture
def mixed_quads() -> Mesh:
    """Separate quads jittered far enough to be concave, bow-ties or folded, with uv, colours and normals."""
    rng = np.random.default_rng(203)
    q = 400
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    corners = square + rng.normal(scale=0.3, size=(q, 4, 3)) + 3 * np.arange(q)[:, None, None] * np.array([1.0, 0, 0])
    normals = np.concatenate([rng.uniform(-0.8, 0.8, (q, 4, 2)), np.ones((q, 4, 1))], axis=2)
    mesh = quads_with_normals(corners, normals)
    mesh.texcoords = rng.uniform(0, 1, (4 * q, 2))
    mesh.corner_texcoord = np.arange(4 * q)
    mesh.colors = rng.uniform(0, 1, (4 * q, 3))
    return mesh


@pytest.mark.parametrize("code", ["Q101", "Q102", "Q103", "Q201", "Q202", "Q203", "Q204", "Q301", "Q302"])
def test_no_check_reads_its_own_threshold(code, mixed_quads):
    """A check is a pure measure: the same rows and values whatever the rule's threshold (lint compares)."""
    check = RULES[code].check
    readings = [check(batch_of(mixed_quads, Settings(thresholds={code: t}))) for t in (-1e9, 0.0, 180.0, 1e9)]
    rows = [np.arange(400)[measured.rows] for measured in readings]
    assert len(rows[0]) > 0
    for measured, taken in zip(readings[1:], rows[1:]):
        np.testing.assert_array_equal(taken, rows[0])
        np.testing.assert_array_equal(measured.values, readings[0].values)


@pytest.mark.parametrize("code", [code for code, rule in RULES.items() if rule.bound is not None])
def test_a_rules_bound_never_hides_a_finding(code, mixed_quads, monkeypatch):
    """A bound only spares measuring quads it proves unflagged: at every threshold, lint with the bound finds
    exactly what lint measuring every quad finds (the bound is also a true bound of each measured value)."""
    from dataclasses import replace

    rule = RULES[code]
    batch = batch_of(mixed_quads, Settings())
    measured = rule.check(batch)
    bound = rule.bound(batch)[np.arange(len(batch))[measured.rows]]
    assert np.all(measured.values <= bound if rule.flags == "above" else measured.values >= bound)
    values = np.sort(measured.values)
    thresholds = [-1e9, 0.0, *values[::40], *np.nextafter(values[::40], np.inf), 179.999, 180.0, 1e9]
    for threshold in thresholds:
        settings = Settings(select=[code], thresholds={code: float(threshold)})
        with_bound = lint_mesh(mixed_quads, settings, visible=False)
        monkeypatch.setitem(RULES, code, replace(rule, bound=None))
        everything = lint_mesh(mixed_quads, settings, visible=False)
        monkeypatch.setitem(RULES, code, rule)
        assert [(h.code, h.faces.tolist(), h.values.tolist()) for h in with_bound] == \
               [(h.code, h.faces.tolist(), h.values.tolist()) for h in everything]
    concave = lint_mesh(mixed_quads, Settings(select=[code]), visible=False)
    assert concave and 0 < len(concave[0].faces) < 400  # the default threshold flags some quads, not all
