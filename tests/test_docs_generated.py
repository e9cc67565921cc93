"""The README and docs/*.md say what the code does: their shell examples run, their configuration blocks
load, and their tables are the ones the benchmark scripts write.

- Every fenced ``sh`` block runs, command by command, from a temporary directory holding what the examples
  read of a checkout (``affinity/data/demo``); a command must exit 0, or the status its trailing
  ``# exit N`` comment names.
  A block preceded by ``<!-- not-run: reason -->`` (installs, clusters, long runs) is not run;
  ``console`` blocks are examples of output.
- Every ``toml`` block loads through the configuration reader as the file it is: ``pyproject.toml`` when
  it has a ``[tool.affinity]`` table, else ``affinity.toml``.
- Every ``<!-- generated: benchmarks/X.py -->`` ... ``<!-- end generated -->`` block equals
  ``reports/bench/X.md``, and ``python benchmarks/X.py --small --out DIR`` writes a table of the same
  shape (its header and column count) to ``DIR/X.md``.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from affinity.cli import main
from affinity.config import read_config

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
GENERATED = re.compile(r"^<!-- generated: benchmarks/(?P<stem>[\w-]+)\.py -->\n(?P<body>.*?)^<!-- end generated -->$",
                       re.S | re.M)
NOT_RUN = re.compile(r"<!-- not-run: .+ -->\s*$")
SHELL_SYNTAX = re.compile(r"[|&;<>$`*]")


def blocks(lang: str) -> list[tuple[str, str, bool]]:
    """``(where, body, marked not-run)`` of every ``lang`` block in the docs."""
    found = []
    for path in DOCS:
        text = path.read_text()
        for match in re.finditer(r"^```(?P<lang>[a-z]*)\n(?P<body>.*?)^```$", text, re.S | re.M):
            if match["lang"] == lang:
                line = text.count("\n", 0, match.start()) + 1
                preceding = text[: match.start()].rstrip("\n").rsplit("\n", 1)[-1]
                found.append((f"{path.name}:{line}", match["body"], bool(NOT_RUN.search(preceding))))
    return found


def commands(body: str) -> list[tuple[str, int]]:
    """The block's commands (``\\`` continuations joined, comment lines dropped) and the status each expects."""
    joined = re.sub(r"\\\n\s*", " ", body)
    found = []
    for line in joined.splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        expected = re.search(r"#\s*exit (\d+)\s*$", line)
        found.append((line, int(expected[1]) if expected else 0))
    return found


def test_the_docs_have_blocks_of_each_kind():
    """The collection below is really reading the files (a regex that matched nothing would pass every test)."""
    assert len(blocks("sh")) >= 5 and len(blocks("toml")) >= 2
    assert any(GENERATED.search(path.read_text()) for path in DOCS)
    assert commands("a \\\n  b  # exit 1\n# c\nd\n") == [("a  b  # exit 1", 1), ("d", 0)]


def _workspace(tmp_path: Path) -> Path:
    """A clean directory with the parts of a checkout the examples read."""
    shutil.copytree(ROOT / "affinity" / "data" / "demo", tmp_path / "affinity" / "data" / "demo")
    return tmp_path


def _run(command: str, cwd: Path, capfd) -> tuple[int, str]:
    """Run one command: ``affinity ...`` without shell syntax in this process, anything else in bash."""
    words = shlex.split(command, comments=True)
    if words[0] == "affinity" and not SHELL_SYNTAX.search(command.split("#", 1)[0]):
        try:
            status = main(words[1:])
        except SystemExit as stop:  # argparse
            status = stop.code
        return status, capfd.readouterr().err
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    result = subprocess.run(["bash", "-c", command], cwd=cwd, capture_output=True, text=True, env=env, timeout=300)
    return result.returncode, result.stderr


@pytest.mark.parametrize("where, body, not_run", blocks("sh"), ids=[b[0] for b in blocks("sh")])
def test_every_shell_block_runs(where, body, not_run, tmp_path, monkeypatch, capfd):
    if not_run:
        pytest.skip(f"{where} is marked not-run")
    cwd = _workspace(tmp_path)
    monkeypatch.chdir(cwd)
    monkeypatch.setenv("AFFINITY_CACHE_DIR", str(tmp_path / "cache"))
    for command, expected in commands(body):
        status, err = _run(command, cwd, capfd)
        assert status == expected and "Traceback" not in err, f"{where}: `{command}` exited {status}:\n{err}"


@pytest.mark.parametrize("where, body, _", blocks("toml"), ids=[b[0] for b in blocks("toml")])
def test_every_toml_block_is_a_valid_configuration(where, body, _, tmp_path):
    name = "pyproject.toml" if re.search(r"^\[tool\.affinity", body, re.M) else "affinity.toml"
    (tmp_path / name).write_text(body)
    options = read_config(tmp_path / name)  # raises ConfigError (exit 2) for anything it does not accept
    assert options["root"] == str(tmp_path) and len(options) > 1, f"{where}: sets nothing"


def generated_blocks() -> list[tuple[str, str, str]]:
    return [(f"{path.name}:{m['stem']}", m["stem"], m["body"]) for path in DOCS
            for m in GENERATED.finditer(path.read_text())]


@pytest.mark.parametrize("where, stem, body", generated_blocks(), ids=[b[0] for b in generated_blocks()])
def test_every_generated_table_is_the_recorded_one(where, stem, body):
    recorded = ROOT / "reports" / "bench" / f"{stem}.md"
    assert recorded.is_file(), f"{where}: run python benchmarks/{stem}.py to record {recorded.name}"
    assert body == recorded.read_text(), f"{where}: the docs differ from {recorded}: paste it again"


def table_shape(text: str) -> tuple[str, int]:
    """The header row of the first Markdown table in ``text`` and its number of columns."""
    rows = [line for line in text.splitlines() if line.startswith("|")]
    assert len(rows) >= 3, "a header, the separator and at least one row"
    return rows[0], rows[1].count("|") - 1


@pytest.mark.slow  # every benchmark script, each in processes of its own
@pytest.mark.parametrize("stem", sorted({b[1] for b in generated_blocks()}))
def test_every_generating_script_runs_small(stem, tmp_path):
    script = ROOT / "benchmarks" / f"{stem}.py"
    result = subprocess.run([sys.executable, str(script), "--small", "--out", str(tmp_path)],
                            cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert table_shape((tmp_path / f"{stem}.md").read_text()) == table_shape(
        (ROOT / "reports" / "bench" / f"{stem}.md").read_text())


def test_the_quick_start_is_two_commands_and_ci_runs_the_second():
    readme = (ROOT / "README.md").read_text()
    quick = readme.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    two = [body for lang, body in re.findall(r"^```(\w*)\n(.*?)^```$", quick, re.S | re.M) if lang == "sh"][-1]
    first, second = two.strip().splitlines()
    assert "affinity report" in first and "pytest" in second
    assert second in (ROOT / ".ci" / "run").read_text().splitlines()
    assert re.search(r"Python (3\.1\d|>= ?3\.10)", quick) and "pyvista" in quick
