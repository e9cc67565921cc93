"""Running `affinity` as a user does (a subprocess) on small OBJ files written into a test's folder."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

SQUARE = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"


TRAPEZOID = "v -1 0 0\nv 1 0 0\nv 0.5 1 0\nv -0.5 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "affinity.cli", *args],
        capture_output=True, text=True, cwd=cwd, timeout=300,
    )


def run_without(module: str, *args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``affinity ARGS`` in a process where ``module`` cannot be imported (an extra not installed)."""
    script = (f"import sys; sys.modules[{module!r}] = None\n"
              "from affinity.cli import main\n"
              f"sys.exit(main({list(args)!r}))\n")
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=cwd, check=False)


def write(tmp_path: Path, name: str, text: str | bytes) -> Path:
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    return path
