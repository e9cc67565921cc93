"""The package graph is the layer map of design.md, and affinity/ stays small at its top.

Imports are read with ``ast`` from every module, lazy ones inside functions included,
so an upward import cannot hide in a function body.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: design.md, "Contracts that checks outside the test suite rely on": lowest first.
#: A module not named here is core.
LAYERS = {
    "render": 0,
    "affinity.draw": 2, "affinity.pipeline": 2,
    "affinity.study": 3, "affinity.view": 3, "affinity.stability": 3, "affinity.blender": 3,
    "affinity.report": 4,
    "affinity.commands": 5,
    "affinity.cli": 6,
    "affinity": 7,  # the package's __init__ only: it re-exports lazily from the layers below
}
CORE = 1
#: Layers whose packages sit side by side: one may not import the other.
SIDE_BY_SIDE = {2, 3}
MAX_TOP_LEVEL_MODULES = 13


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def unit_of(module: str) -> str:
    """The layered unit a module belongs to: its entry in LAYERS, or the core module itself."""
    if module == "affinity":
        return "affinity"
    for unit in sorted(LAYERS, key=len, reverse=True):
        if unit != "affinity" and (module == unit or module.startswith(unit + ".")):
            return unit
    return module


def layer_of(module: str) -> int:
    return LAYERS.get(unit_of(module), CORE)


def imported_modules(path: Path, module: str | None = None) -> list[tuple[int, str]]:
    """(line, absolute module) of every project import in the file, relative ones resolved.

    ``module`` is the file's dotted name (default: from its place under ROOT).
    """
    module = module or module_name(path)
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            target = ".".join([*base, *([node.module] if node.module else [])])
            # "from . import lint" imports the module affinity.lint
            found += [(node.lineno, target if node.module else f"{target}.{alias.name}") for alias in node.names]
    return [(line, name) for line, name in found if name.split(".")[0] in ("affinity", "render")]


def wrong_imports(path: Path, module: str | None = None) -> list[str]:
    """One line per import of ``path`` that points up the layers or across to a side-by-side package."""
    here = module or module_name(path)
    wrong = []
    for line, target in imported_modules(path, here):
        source_layer, target_layer = layer_of(here), layer_of(target)
        if target_layer > source_layer:
            wrong.append(f"{path.name}:{line}: {here} (layer {source_layer}) imports {target} (layer {target_layer})")
        elif source_layer == target_layer and source_layer in SIDE_BY_SIDE and unit_of(here) != unit_of(target):
            wrong.append(f"{path.name}:{line}: {here} imports {target}, side by side with it")
    return wrong


def project_modules() -> list[Path]:
    return sorted([*(ROOT / "affinity").rglob("*.py"), *(ROOT / "render").rglob("*.py")])


def test_no_import_points_up_the_layers():
    wrong = [line for path in project_modules() for line in wrong_imports(path)]
    assert not wrong, "\n".join(wrong)


def test_the_layer_check_sees_lazy_and_relative_imports(tmp_path):
    """The checker itself, on modules it must reject and accept."""
    source = tmp_path / "measures.py"
    source.write_text("import numpy\n\ndef f():\n    from .report import build\n    from . import lint\n")
    assert wrong_imports(source, "affinity.measures") == [
        "measures.py:4: affinity.measures (layer 1) imports affinity.report (layer 4)"]
    source.write_text("def f():\n    from ..pipeline.check import check_file\n")
    assert wrong_imports(source, "affinity.draw.drawing") == [
        "measures.py:2: affinity.draw.drawing imports affinity.pipeline.check, side by side with it"]
    source.write_text("def f():\n    from ..lint import lint_mesh\n    import render\n")
    assert wrong_imports(source, "affinity.draw.drawing") == []


def test_render_knows_nothing_of_affinity():
    for path in (ROOT / "render").rglob("*.py"):
        assert not [name for _, name in imported_modules(path) if name.startswith("affinity")], path


def test_affinity_stays_small_at_the_top():
    modules = sorted(p.name for p in (ROOT / "affinity").glob("*.py") if p.name != "__init__.py")
    assert len(modules) <= MAX_TOP_LEVEL_MODULES, f"{len(modules)} top-level modules: {modules}; use the subpackages"


@pytest.mark.parametrize("name", ["render_mesh", "RenderOptions"])
def test_the_package_root_exports_lazily(name):
    import subprocess
    import sys

    code = (f"import sys, affinity; assert 'affinity.draw' not in sys.modules; "
            f"print(affinity.{name}.__module__)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "affinity.draw.drawing"


def test_the_design_contract_call(tmp_path):
    """design.md: render_mesh(path, RenderOptions(...)) from the package root, show="uv" puts uv in frame.attrs."""
    import numpy as np

    from affinity import RenderOptions, render_mesh

    obj = tmp_path / "square.obj"
    obj.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")
    result = render_mesh(str(obj), RenderOptions(method="split", show="uv", width=64, height=64,
                                                 camera=((0, 0, 5), (0, 0, 0), 40.0), up="y", cull=False))
    covered = result.frame.face >= 0
    assert covered.sum() > 100
    assert result.faces.tolist() == [0] and result.methods.tolist() == ["split"]
    # The square spans x, y in [-1, 1] and its uv is (x + 1) / 2, (y + 1) / 2: an affine map, so the split is exact.
    rows, cols = np.nonzero(covered)
    u = result.frame.attrs[rows, cols, 0]
    assert np.all(np.diff(u[rows == rows[0]]) > 0), "u grows to the right"
    v = result.frame.attrs[rows, cols, 1]
    assert v[rows == rows.min()].mean() > v[rows == rows.max()].mean(), "v grows upward (row 0 is the top)"


def test_no_private_name_is_imported_across_modules():
    private = []
    for path in project_modules():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] in ("affinity", "render", ""):
                private += [f"{path.relative_to(ROOT)}:{node.lineno}: {alias.name}" for alias in node.names
                            if alias.name.startswith("_") and alias.name != "__version__"]
    assert not private, "\n".join(private)
