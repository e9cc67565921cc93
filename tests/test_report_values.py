"""The report is built from values (issue 39): one lint per mesh gives the findings and every quad's scores,
the per-mesh result and each close-up are frozen records assembled once, every render routes by the settings
given to the report, ``report/`` reaches ``draw/`` through its public names only, and no rule code is written
into either package: the registries decide what is shown."""

from __future__ import annotations

import ast
import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

import affinity.draw
from affinity.report.build import ReportOptions, collect_mesh
from affinity.report.demo import MeshInput
from affinity.settings import Settings

ROOT = Path(__file__).resolve().parents[1]
SMALL = ReportOptions(size=(96, 72), max_views=3)

#: A trapezoid 2 wide at the bottom and 1 at the top whose corners carry the unit square as the colours (s, t, 0).
COLOUR_TRAPEZOID = "v -1 0 0 0 0 0\nv 1 0 0 1 0 0\nv 0.5 1 0 1 1 0\nv -0.5 1 0 0 1 0\nf 1 2 3 4\n"


def colour_steps(width: float = 1.0) -> float:
    """Q102 of the trapezoid: its colours are the unit square, so the split error is the uv's closed form
    (1 - r) / (1 + sqrt r)^2, r = width / 2 (tests/test_measures_error.py), in 1/255 steps."""
    r = width / 2
    return 255 * (1 - r) / (1 + math.sqrt(r)) ** 2


def colour_only(tmp_path: Path) -> Path:
    """The trapezoid with its colours only (no uv, no normals): the report draws and routes its colours."""
    path = tmp_path / "colours.obj"
    path.write_text(COLOUR_TRAPEZOID)
    return path


def test_the_trapezoids_colour_error_is_the_closed_form(tmp_path):
    from affinity.lint import quad_scores
    from affinity.loaders import load

    scores = quad_scores(load(str(colour_only(tmp_path))), Settings(), "Q102")
    assert scores.values == pytest.approx([colour_steps()], rel=1e-9)  # about 43.8 steps: far from 100


def test_a_threshold_given_to_collect_mesh_routes_the_report_s_renders(tmp_path):
    """Q102 at 100 steps does not flag the trapezoid's 43.8: its hybrid render is all split; at the default
    2 it goes to mvc. (Before, every render resolved the file's configuration again and routed at 2.)"""
    path = colour_only(tmp_path)
    item = MeshInput(str(path), path.name)
    lenient = collect_mesh(item, Settings(thresholds={"Q102": 100.0}), options=SMALL)
    strict = collect_mesh(item, Settings(), options=SMALL)
    assert lenient.drawn == strict.drawn == "color"
    assert set(lenient.renders["hybrid"].methods) == {"split"} and not lenient.file.hits
    assert set(strict.renders["hybrid"].methods) == {"mvc"} and [h.code for h in strict.file.hits] == ["Q102"]
    assert [view.place.code for view in strict.closeups] == ["Q102"]
    assert set(strict.closeups[0].images) == {"split", "hybrid", "exact"}


def test_the_report_s_settings_win_over_the_folder_s_configuration_and_are_resolved_once(tmp_path, monkeypatch):
    """A configuration beside the mesh that would not flag it does not reach a report given other settings:
    nothing re-reads it (before: up to 22 resolutions a mesh, and the render routed by the file's)."""
    import affinity.config

    (tmp_path / "affinity.toml").write_text("[thresholds]\nQ102 = 100\n")
    path = colour_only(tmp_path)
    resolved = []
    real = affinity.config.file_settings
    monkeypatch.setattr(affinity.config, "file_settings", lambda *a, **k: resolved.append(a) or real(*a, **k))
    result = collect_mesh(MeshInput(str(path), path.name), Settings(), options=SMALL)
    assert set(result.renders["hybrid"].methods) == {"mvc"}
    assert resolved == []


def three_trapezoids(tmp_path: Path) -> Path:
    """Three separate trapezoids with uv, colours and normals: the first creased in its colours only (the uv
    an affine image of the positions, the normals equal), the second in its normals only, the third in its uv
    only (the unit square). Faces 0, 1, 2."""
    corners = np.array([[-1, 0, 0], [1, 0, 0], [0.5, 1, 0], [-0.5, 1, 0]], dtype=float)
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    lean = [[0, 0, 1], [0.4, 0, 1], [0.4, 0.4, 1], [0, 0.4, 1]]
    lines = []
    for k in range(3):
        at = corners + [3.0 * k, 0, 0]
        colours = np.c_[square, np.zeros(4)] if k == 0 else np.full((4, 3), 0.5)
        uv = square if k == 2 else at[:, :2] / 4 + 0.5
        normals = lean if k == 1 else [[0, 0, 1]] * 4
        lines += [f"v {p[0]} {p[1]} {p[2]} {c[0]} {c[1]} {c[2]}" for p, c in zip(at, colours)]
        lines += [f"vt {u} {v}" for u, v in uv] + [f"vn {x} {y} {z}" for x, y, z in normals]
        lines.append("f " + " ".join(f"{4 * k + i}/{4 * k + i}/{4 * k + i}" for i in range(1, 5)))
    path = tmp_path / "three.obj"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_one_lint_per_mesh_gives_the_findings_and_every_quad_s_scores(tmp_path, monkeypatch):
    """A mesh with uv, colours and normals, each flagged on its own quad: the report lints it once (the
    close-ups' colour and normal routing measure their own quads, they do not lint); the scores of every
    scored rule cover every quad, flagged or not, and agree with the findings of the same pass."""
    import affinity.lint

    path = three_trapezoids(tmp_path)
    linted = []
    real = affinity.lint.lint_pass

    def counted(mesh, *args, **kwargs):
        linted.append(mesh.path)
        return real(mesh, *args, **kwargs)

    monkeypatch.setattr(affinity.lint, "lint_pass", counted)
    result = collect_mesh(MeshInput(str(path), path.name), Settings(), options=SMALL)
    assert linted == [str(path)]
    assert list(result.scores) == ["Q101", "Q102", "Q103"]
    hits = {h.code: h for h in result.file.hits}
    assert {code: h.faces.tolist() for code, h in hits.items()} == {"Q101": [2], "Q102": [0], "Q103": [1]}
    for code, scores in result.scores.items():
        assert scores.faces.tolist() == [0, 1, 2]
        assert scores.faces[scores.flagged].tolist() == hits[code].faces.tolist()
        if code != "Q101":  # Q101's finding reads the texture where one decodes; its score is the shift
            np.testing.assert_array_equal(scores.values[scores.flagged], hits[code].values)
    assert result.scores["Q102"].values == pytest.approx([colour_steps(), 0, 0], rel=1e-9, abs=1e-9)
    assert sorted(view.place.code for view in result.closeups) == ["Q101", "Q102", "Q103"]


def test_the_result_and_every_closeup_are_frozen_records(tmp_path):
    from affinity.draw import Closeup
    from affinity.report.build import MeshResult

    path = three_trapezoids(tmp_path)
    result = collect_mesh(MeshInput(str(path), path.name), Settings(), options=SMALL)
    for record, kind in ((result, MeshResult), (result.closeups[0], Closeup)):
        assert dataclasses.is_dataclass(kind) and kind.__dataclass_params__.frozen
        for name in ("place" if kind is Closeup else "closeups", "images" if kind is Closeup else "shown"):
            assert name in {f.name for f in dataclasses.fields(kind)}
            with pytest.raises(dataclasses.FrozenInstanceError):
                setattr(record, name, None)


def _draw_imports(path: Path) -> list[tuple[str, list[str]]]:
    """(module, names) of every import of affinity.draw or below it in ``path``, lazy ones included."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level == 2 and (node.module or "").startswith("draw"):
            found.append((node.module, [alias.name for alias in node.names]))
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("affinity.draw"):
            found.append((node.module.removeprefix("affinity."), [alias.name for alias in node.names]))
        elif isinstance(node, ast.Import):
            found += [(alias.name, []) for alias in node.names if alias.name.startswith("affinity.draw")]
    return found


def test_report_uses_only_the_names_draw_exports():
    public = set(affinity.draw.__all__)
    wrong = [f"{path.name}: {module} {names}" for path in sorted((ROOT / "affinity" / "report").glob("*.py"))
             for module, names in _draw_imports(path) if module != "draw" or not set(names) <= public]
    assert wrong == []
    assert all(hasattr(affinity.draw, name) for name in public)


def test_the_checker_finds_a_reach_into_a_draw_module(tmp_path):
    source = tmp_path / "reaching.py"
    source.write_text("def f():\n    from ..draw.closeup import outline\n    from ..draw import closeup\n")
    assert _draw_imports(source) == [("draw.closeup", ["outline"]), ("draw", ["closeup"])]


def test_no_rule_code_is_written_where_things_are_shown():
    """What is shown and how comes from the registries (any file type: templates and scripts too): report/,
    draw/, study/, blender/ and the pyvista view."""
    literal = re.compile(r"[\"']Q10[1-3][\"']")
    hits = [f"{path.relative_to(ROOT)}:{n}" for package in ("report", "draw", "study", "blender", "view")
            for path in sorted((ROOT / "affinity" / package).rglob("*"))
            if path.is_file() and "vendor" not in path.parts
            for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1) if literal.search(line)]
    assert hits == []
