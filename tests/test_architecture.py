"""The package graph is the layer map of design.md, the module graph has no cycle, and affinity/
stays small at its top.

Imports are read with ``ast`` from every module, lazy ones inside functions included (and those
under ``TYPE_CHECKING``), so an upward import or a cycle cannot hide in a function body.
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
MAX_TOP_LEVEL_MODULES = 12


def module_name(path: Path, root: Path = ROOT) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
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
    found = [entry for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
             if isinstance(node, (ast.Import, ast.ImportFrom)) for entry in statement_imports(node, module, path)]
    return [(line, name) for line, name in found if name.split(".")[0] in ("affinity", "render")]


def statement_imports(node: ast.Import | ast.ImportFrom, module: str, path: Path) -> list[tuple[int, str]]:
    """(line, absolute module) of one import statement of the file ``path`` (dotted name ``module``),
    relative ones resolved: ``from X import a, b`` gives (line, X) once, ``from . import lint`` the
    module ``package.lint``."""
    if isinstance(node, ast.Import):
        return [(node.lineno, alias.name) for alias in node.names]
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    base = package[: len(package) - node.level + 1] if node.level else []
    target = ".".join([*base, *([node.module] if node.module else [])])
    if node.module is None:
        return [(node.lineno, f"{target}.{alias.name}") for alias in node.names]
    return [(node.lineno, target)]


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


def module_graph(paths: list[Path], root: Path = ROOT) -> dict[str, set[str]]:
    """Module -> the modules among ``paths`` (files under ``root``) it imports. ``from package
    import name`` points at the module ``package.name`` where there is one (a submodule), else at
    ``package`` (its ``__init__``, which defines or imports the name). Importing a module runs the
    ``__init__`` of every package above it first: a module also points at those packages (all but
    the ones it sits in, whose ``__init__`` has run before it)."""
    names = {module_name(path, root): path for path in paths}
    graph = {}
    for name, path in names.items():
        targets = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, (ast.Import, ast.ImportFrom)):
                continue
            for _, target in statement_imports(node, name, path):
                if isinstance(node, ast.ImportFrom) and node.module is None:  # from . import name
                    targets.add(target if target in names else target.rpartition(".")[0])
                elif isinstance(node, ast.ImportFrom):
                    submodules = {f"{target}.{alias.name}" for alias in node.names} & names.keys()
                    targets |= {target} if len(submodules) < len(node.names) else set()
                    targets |= submodules
                else:
                    targets.add(target)
        targets |= {package for target in targets for package in enclosing_packages(target)
                    if not (name == package or name.startswith(package + "."))}
        graph[name] = {target for target in targets if target in names and target != name}
    return graph


def enclosing_packages(module: str) -> list[str]:
    """The packages ``module`` sits in, outermost first: ``a.b.c`` -> ``a``, ``a.b``."""
    parts = module.split(".")
    return [".".join(parts[:k]) for k in range(1, len(parts))]


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (and the modules importing
    themselves), each sorted: Tarjan's algorithm, iterative so a deep graph cannot overflow."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, successors = work[-1]
            for successor in successors:
                if successor not in index:
                    index[successor] = low[successor] = len(index)
                    stack.append(successor)
                    on_stack.add(successor)
                    work.append((successor, iter(sorted(graph[successor]))))
                    break
                if successor in on_stack:
                    low[node] = min(low[node], index[successor])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1 or node in graph[node]:
                        found.append(sorted(component))
    return sorted(found)


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


def test_no_module_imports_itself_back():
    """No cycle in the module graph of affinity/ and render/, lazy imports included: each module can
    be read, tested and moved with only what it imports below it."""
    graph = module_graph(project_modules())
    found = cycles(graph)
    assert not found, "\n".join(
        "cycle: " + "; ".join(f"{m} imports {', '.join(sorted(graph[m] & set(c)))}" for m in c) for c in found)


def test_the_cycle_check_sees_lazy_and_relative_imports(tmp_path):
    """The graph and Tarjan's components on a package the test writes: a lazy import closing a
    cycle of three, a module importing its package's __init__, and an acyclic part."""
    package = tmp_path / "pkg"
    package.mkdir()
    files = {
        "__init__.py": "from .a import f\n",
        "a.py": "from . import b\n",
        "b.py": "def g():\n    from .c import h\n",
        "c.py": "import pkg.a\nfrom pkg import d\n",
        "d.py": "from . import f\n",  # the package's __init__, which imports a: d -> pkg -> a -> b -> c -> d
        "e.py": "from .d import x\n",
    }
    for name, text in files.items():
        (package / name).write_text(text)
    graph = module_graph(sorted(package.glob("*.py")), tmp_path)
    assert graph["pkg.c"] == {"pkg.a", "pkg.d"} and graph["pkg.d"] == {"pkg"} and graph["pkg.b"] == {"pkg.c"}
    assert cycles(graph) == [["pkg", "pkg.a", "pkg.b", "pkg.c", "pkg.d"]]
    (package / "d.py").write_text("x = 1\n")
    (package / "b.py").write_text("x = 1\n")
    graph = module_graph(sorted(package.glob("*.py")), tmp_path)
    assert cycles(graph) == []
    assert cycles({"a": {"a"}}) == [["a"]]


def test_the_cycle_check_follows_package_inits(tmp_path):
    """Importing ``pkg.output.names`` runs ``pkg/output/__init__.py``: issue 51's ``rules.file -> output.names
    -> output/__init__ -> rules`` is a cycle, though no module imports ``rules.file``'s importer by name."""
    files = {
        "pkg/__init__.py": "",
        "pkg/rules/__init__.py": "from . import file\n",
        "pkg/rules/file.py": "def f():\n    from ..output.names import printable\n",
        "pkg/output/__init__.py": "from ..rules import f\nfrom .names import printable\n",
        "pkg/output/names.py": "def printable(name):\n    return name\n",
    }
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    paths = sorted(tmp_path.rglob("*.py"))
    graph = module_graph(paths, tmp_path)
    assert graph["pkg.rules.file"] == {"pkg.output", "pkg.output.names"}
    assert graph["pkg.output.names"] == set()  # inside pkg.output: its __init__ ran first
    assert cycles(graph) == [["pkg.output", "pkg.rules", "pkg.rules.file"]]
    (tmp_path / "pkg/rules/file.py").write_text("def f():\n    from ..names import printable\n")
    (tmp_path / "pkg/names.py").write_text("def printable(name):\n    return name\n")
    assert cycles(module_graph(sorted(tmp_path.rglob("*.py")), tmp_path)) == []


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


#: The modules a lint runs through, from the mesh's tables to the settled findings.
LINT_PATH = ["affinity/lint.py", "affinity/findings.py", "affinity/measures.py", "affinity/geometry.py",
             "affinity/attributes.py", "affinity/rules/*.py", "affinity/textures/reading.py"]


def mutators(source: str) -> list[str]:
    """``name:line`` of each function in ``source`` that writes into one of its arguments or the items
    a loop takes from one (an attribute or item assignment, in-place arithmetic, ``append``/``update``/...),
    whether or not it also returns something. A parameter named ``out`` is NumPy's convention for a
    caller's buffer, and is not counted."""
    found = []
    for function in ast.walk(ast.parse(source)):
        if not isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        arguments = {a.arg for a in [*function.args.posonlyargs, *function.args.args, *function.args.kwonlyargs]}
        arguments -= {"self", "cls", "out"}
        arguments |= {name.id for node in ast.walk(function)  # for h in hits: each h is the caller's
                      if isinstance(node, ast.For) and isinstance(node.iter, ast.Name) and node.iter.id in arguments
                      for name in ast.walk(node.target) if isinstance(name, ast.Name)}
        for node in ast.walk(function):
            targets = node.targets if isinstance(node, ast.Assign) else [
                node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
            written = [element for target in targets
                       for element in (target.elts if isinstance(target, ast.Tuple) else [target])
                       if isinstance(element, (ast.Attribute, ast.Subscript))]
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr in ("append", "extend", "update", "setdefault", "insert", "add", "clear")):
                written.append(node.func)
            for target in written:
                while isinstance(target, (ast.Attribute, ast.Subscript)):
                    target = target.value
                if isinstance(target, ast.Name) and target.id in arguments:
                    found.append(f"{function.name}:{node.lineno}")
                    break
    return list(dict.fromkeys(found))


def test_no_function_on_the_lint_path_writes_into_its_input():
    """A caller reads what a lint step computed from what it returns, and its own values stay as they were
    (issue 39: settle set its input hits' levels, the visible reading rewrote Q101's hits in place)."""
    found = [f"{path.relative_to(ROOT)}:{where}" for pattern in LINT_PATH for path in sorted(ROOT.glob(pattern))
             for where in mutators(path.read_text(encoding="utf-8"))]
    assert not found, "\n".join(found)


def test_the_mutation_check_sees_writes_into_arguments():
    source = ("def settle(hits, settings):\n    for h in hits:\n        h.level = 1\n    return hits\n"
              "def cap(E, folded):\n    E[:, folded] *= 2\n"
              "def note(details, row):\n    details.append(row)\n"
              "def fresh(hits):\n    out = list(hits)\n    out[0] = None\n    return out\n"
              "def kernel(table, out):\n    out[:] = table\n"
              "def local(hits):\n    copy = dict(hits)\n    copy[hits[0]] = 1\n")
    assert mutators(source) == ["settle:3", "cap:6", "note:8"]
