"""Rule roles live in the registry (issue 51): what a rule masks, the cause it names, why fix leaves the quads it
flags and which USD validator reports it are fields of its record, and no other module names a rule code.

A test registers two rules of a new validator family: a scored one on the uv and a cause that takes the uv's
scored rules over on some quads, and follows them through lint, fix's plan and the USD validators' findings,
without any other module knowing them.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest
from helpers.sheared_grid import SHIFT, SIDE, TEXTURE, grid_obj

ROOT = Path(__file__).resolve().parents[1]
CODE = re.compile(r"Q\d{3}")


def docstrings(tree: ast.AST) -> set[int]:
    """The ids of the string constants that are docstrings (module, class, function) in ``tree``."""
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value,
                                                                                                    str):
                found.add(id(first.value))
    return found


def code_literals(path: Path) -> list[str]:
    """``path:line: text`` of every string constant naming a rule code that is not a docstring."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skip = docstrings(tree)
    return [f"{path.relative_to(ROOT)}:{node.lineno}: {node.value!r}" for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in skip
            and CODE.search(node.value)]


def test_no_rule_code_is_written_outside_the_rules_package():
    """Codes belong to affinity/rules/; elsewhere only docstrings (and text made from the registry) name them."""
    rules = ROOT / "affinity" / "rules"
    found = [line for path in sorted((ROOT / "affinity").rglob("*.py")) if rules not in path.parents
             for line in code_literals(path)]
    assert found == []


def test_the_scan_sees_a_code_outside_a_docstring(tmp_path):
    """The scan itself: a code in a constant is found, one in a docstring is not."""
    module = ROOT / "affinity" / "probe_for_the_scan.py"
    module.write_text('"""Q101 in a docstring."""\nCAUSES = {"Q201": "it has no area"}\n')
    try:
        assert [line.split(": ", 1)[1] for line in code_literals(module)] == ["'Q201'"]
    finally:
        module.unlink()


def column(quads) -> np.ndarray:
    """(Q,) int64: the grid column of each quad of a batch (its centroid's x, rounded down)."""
    mesh = quads.mesh
    corners = mesh.positions[mesh.corner_vertex[quads.corners]]  # (4, Q, 3)
    return np.floor(corners[..., 0].mean(axis=0)).astype(np.int64)


def marked(quads) -> np.ndarray:
    """(Q,) bool: the quads of the grid's first column: the synthetic cause's defect."""
    return column(quads) == 0


@pytest.fixture
def new_rules():
    """Family ``Synthetic`` with Q998 (scored, uv: three times Q101's shift, threshold 1 texel), Q997 (flags the
    first column and takes the uv's scored rules over there) and Q996 (flags the second column; fix leaves the
    quads it flags ``held``)."""
    from affinity.rules import FAMILIES, Measured, register_family, rule, unregister
    from affinity.rules.affinity import uv_disaffinity

    register_family("Synthetic", "rules registered by a test.")

    page = {"why": "A test.", "example": "v 0 0 0\nf 1 1 1\n", "fix": "Unregister it."}  # each rule's page

    @rule(code="Q998", name="triple-shift", unit="texels", default_threshold=1.0, attribute="texcoords", scored=True,
          family="Synthetic", what="Q101's measure, tripled.", **page)
    def triple_shift(quads) -> Measured:
        """Three times the split's shift."""
        measured = uv_disaffinity(quads)
        return Measured(measured.rows, 3 * measured.values)

    @rule(code="Q997", name="marked-quad", unit="marks", default_threshold=0.5, family="Synthetic",
          masks=("texcoords",), unmeasurable=marked, cause="it is marked", what="Flags the first column.", **page)
    def marked_quad(quads) -> Measured:
        """The quad is marked."""
        return Measured(slice(None), marked(quads).astype(np.float64))

    @rule(code="Q996", name="held-quad", unit="holds", default_threshold=0.5, family="Synthetic", fix_leaves="held",
          fix_precedence=9, what="Flags the second column.", **page)
    def held_quad(quads) -> Measured:
        """The quad is held."""
        return Measured(slice(None), (column(quads) == 1).astype(np.float64))

    try:
        yield
    finally:
        for code in ("Q996", "Q997", "Q998"):
            unregister(code)
        del FAMILIES["Synthetic"]


FIRST_COLUMN = np.arange(SIDE) * SIDE  # the grid's faces at x in [0, 1]
SECOND_COLUMN = FIRST_COLUMN + 1


def test_a_new_scored_rule_and_cause_are_measured_by_lint(new_rules, tmp_path):
    from affinity.lint import lint_mesh
    from affinity.loaders import load
    from affinity.settings import Settings

    mesh = load(str(grid_obj(tmp_path, material=None)))
    hits = {h.code: h for h in lint_mesh(mesh, Settings(texture_size=TEXTURE))}
    others = np.setdiff1d(np.arange(SIDE * SIDE), FIRST_COLUMN)
    np.testing.assert_array_equal(hits["Q998"].faces, others)  # measured, and masked where the cause is
    np.testing.assert_allclose(hits["Q998"].values, 3 * SHIFT, rtol=1e-9)
    np.testing.assert_array_equal(hits["Q101"].faces, others)
    np.testing.assert_array_equal(hits["Q997"].faces, FIRST_COLUMN)
    assert set(hits["Q997"].details) == {"it is marked, so Q101, Q998 are not measured on it"}
    np.testing.assert_array_equal(hits["Q996"].faces, SECOND_COLUMN)
    assert hits["Q996"].details is None  # not a cause


def test_a_new_scored_rule_is_refined_and_a_new_cause_left_by_fix(new_rules, tmp_path):
    """Q998 reads 3.2 texels against 1: the 1/n^2 law of the bilinear term puts n = 2 at 0.8 (Q101's 1.07 against
    0.5 reads less beyond its threshold), rounded up to the odd 3 that closes to quads; the held column is left
    with Q996's reason; the marked one has no scored finding to fix."""
    from affinity.fix import FixSettings, plan_fix
    from affinity.loaders import load
    from affinity.settings import Settings

    mesh = load(str(grid_obj(tmp_path, material=None)))
    plan = plan_fix(mesh, FixSettings(lint=Settings(texture_size=TEXTURE)))
    np.testing.assert_array_equal(plan.left_faces, SECOND_COLUMN)
    assert set(plan.left_reasons) == {"held"}
    np.testing.assert_array_equal(plan.refine_faces,
                                  np.setdiff1d(np.arange(SIDE * SIDE), np.r_[FIRST_COLUMN, SECOND_COLUMN]))
    assert set(plan.refine_n) == {3}
    assert set(plan.codes) == {"Q998"}
    np.testing.assert_allclose(plan.before, 3 * SHIFT, rtol=1e-9)
    np.testing.assert_allclose(plan.after, 3 * SHIFT / 9, rtol=1e-6)  # the 1/n^2 law at n = 3


def test_a_new_family_is_reported_by_the_usd_validators(new_rules, tmp_path):
    """The USD validators' findings (what UsdValidation and the NVIDIA rules report) of the new family hold its
    rules' findings on a USD stage of the grid."""
    pytest.importorskip("pxr", reason="needs the usd extra (usd-core)")
    from pxr import Sdf, Usd, UsdGeom

    from affinity.usd.families import families
    from affinity.usd.stage import family_findings

    path = tmp_path / "grid.usda"
    stage = Usd.Stage.CreateNew(str(path))
    mesh = UsdGeom.Mesh.Define(stage, "/Grid")
    x, y = np.meshgrid(np.arange(SIDE + 1.0), np.arange(SIDE + 1.0))
    mesh.GetPointsAttr().Set([(float(a), float(b), 0.0) for a, b in zip(x.ravel(), y.ravel())])
    corner = (np.arange(SIDE)[:, None] * (SIDE + 1) + np.arange(SIDE)).ravel()
    mesh.GetFaceVertexCountsAttr().Set([4] * SIDE * SIDE)
    mesh.GetFaceVertexIndicesAttr().Set(np.stack([corner, corner + 1, corner + SIDE + 2, corner + SIDE + 1],
                                                 axis=1).ravel().tolist())
    mesh.GetSubdivisionSchemeAttr().Set("none")
    uv = [(a / SIDE + 0.6 * a * b / SIDE ** 2, b / SIDE) for a, b in zip(x.ravel(), y.ravel())]
    UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                            UsdGeom.Tokens.vertex).Set(uv)
    stage.GetRootLayer().Save()

    [family] = [f for f in families() if f.name == "Synthetic"]
    assert family.codes == ("Q996", "Q997", "Q998") and not family.fixable
    assert family.doc == "quad-affinity Q996-Q998: rules registered by a test."
    opened = Usd.Stage.Open(str(path))
    said = family_findings(family, opened.GetPrimAtPath("/Grid"))
    faces = {code: sorted(f.face for f in said.findings if f.code == code) for code in family.codes}
    assert faces["Q996"] == SECOND_COLUMN.tolist() and faces["Q997"] == FIRST_COLUMN.tolist()
    assert faces["Q998"] == np.setdiff1d(np.arange(SIDE * SIDE), FIRST_COLUMN).tolist()
