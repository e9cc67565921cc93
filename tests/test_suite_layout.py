"""The test suite's own layout: shared helpers live in ``tests/helpers/``, no test module imports another,
the path of the real meshes is spelled in one place (``helpers.corpus``), and the command line runs in the
test's process except in the modules that test the process itself."""

from __future__ import annotations

import ast
import itertools
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
TEST_MODULES = sorted(TESTS.glob("test_*.py"))
HELPERS = sorted((TESTS / "helpers").glob("*.py"))
LOCAL_MODULES = {path.stem for path in TESTS.glob("*.py")} - {"conftest"}


def imported_modules(path: Path) -> set[str]:
    """Every module ``path`` imports, at any depth of the file (lazy imports included)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            found.add(node.module)
        elif isinstance(node, ast.ImportFrom):
            found.add("." * node.level + (node.module or ""))
    return found


def test_the_check_sees_a_test_module_importing_another(tmp_path):
    """The parser below is really looking: a lazy import of a sibling test module is found."""
    module = tmp_path / "test_x.py"
    module.write_text("def test_a():\n    from test_cli_check import run\n    import test_formats as f\n")
    assert imported_modules(module) == {"test_cli_check", "test_formats"}


@pytest.mark.parametrize("path", TEST_MODULES, ids=lambda p: p.name)
def test_no_test_module_imports_another_module_of_tests(path):
    siblings = {name for name in imported_modules(path) if name.split(".")[0] in LOCAL_MODULES or name.startswith(".")}
    assert not siblings, f"{path.name} imports {sorted(siblings)}: move shared code into tests/helpers/"


@pytest.mark.parametrize("path", HELPERS, ids=lambda p: p.name)
def test_helpers_import_no_test_module(path):
    tests = {name for name in imported_modules(path) if name.split(".")[0] in LOCAL_MODULES}
    assert not tests, f"helpers/{path.name} imports {sorted(tests)}"


def test_only_helpers_sit_beside_the_test_modules():
    """Plain modules in tests/ next to test_*.py are where shared helpers used to hide."""
    assert LOCAL_MODULES == {path.stem for path in TEST_MODULES}


def test_the_shared_meshes_path_is_spelled_once():
    spelling = '"shared" / ' + '"meshes"'  # in two pieces, so this file does not spell it
    spelled = [path.relative_to(TESTS).as_posix() for path in TESTS.rglob("*.py")
               if spelling in path.read_text(encoding="utf-8")]
    assert spelled == ["helpers/corpus.py"]


#: The modules that test the process boundary itself and start ``python -m affinity.cli`` on their own, and
#: why. Every other module runs the command line through ``helpers.cli.run`` (in the test's process: about
#: 0.7 s of start-up less a call) or, where the boundary matters to one test, ``helpers.cli.run_process``.
SPAWNS_ITS_OWN_PROCESS = {
    "test_blender.py": "the check runs beside Blender's own Python",
    "test_broken_inputs.py": "a link to the process's own stdout, read as bytes",
    "test_cluster.py": "a Dask cluster and the environment it is named by",
    "test_farm.py": "journals that survive a killed run",
    "test_fuzz.py": "a time limit on each batch of mutated files",
    "test_huge_values.py": "the interpreter's own -W error",
    "test_merge_untrusted.py": "a time limit on reads that would block",
    "test_pathological_inputs.py": "a time limit on reads that would block",
    "test_signals.py": "signals sent to the running command",
    "test_worker_loss.py": "-j worker processes that die",
}


def spawned_cli_lines(path: Path) -> list[int]:
    """The lines where ``path`` spells an argument list ``[..., "-m", "affinity.cli", ...]``."""
    lines = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, (ast.List, ast.Tuple)):
            words = [element.value if isinstance(element, ast.Constant) else None for element in node.elts]
            if any(pair == ("-m", ".".join(["affinity", "cli"])) for pair in itertools.pairwise(words)):
                lines.append(node.lineno)
    return lines


def test_the_check_sees_a_module_spawning_the_command_line(tmp_path):
    module = tmp_path / "test_x.py"
    module.write_text("import subprocess, sys\n\ndef test_a():\n"
                      "    subprocess.run([sys.executable, '-m', 'affinity.cli', 'check'])\n")
    assert spawned_cli_lines(module) == [4]


def test_the_command_line_runs_in_the_tests_process_but_where_the_process_is_tested():
    spawning = {path.name for path in TEST_MODULES if spawned_cli_lines(path)}
    assert spawning <= set(SPAWNS_ITS_OWN_PROCESS), (
        f"{sorted(spawning - set(SPAWNS_ITS_OWN_PROCESS))} start python -m affinity.cli: use helpers.cli.run, "
        "or helpers.cli.run_process for a test of the process boundary")
