"""The pre-commit hook, run by the real ``pre-commit`` against a snapshot of this checkout.

``pre-commit try-repo`` installs the hook repository into a fresh virtualenv
from a git revision. A snapshot (every file git tracks or would track, as it is
in the working tree) committed to a temporary repository makes that revision
equal to the working tree, uncommitted and untracked files included. Installing
needs PyPI (setuptools, numpy) and nothing else; the pre-commit cache lives in
the temporary folder, so the test is hermetic and takes about a minute.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest
from test_formats import SQUARE, UNIT_UV, quad_obj, trapezoid

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(
    shutil.which("git") is None or shutil.which("pre-commit") is None,
    reason="needs git and pre-commit",
)


def git(*args: str, cwd: Path) -> str:
    return subprocess.run(
        ["git", "-c", "user.name=test", "-c", "user.email=test@example.invalid", "-c", "commit.gpgsign=false",
         *args], cwd=cwd, check=True, capture_output=True, text=True,
    ).stdout


def snapshot(dest: Path) -> Path:
    """A one-commit repository holding this checkout's working tree (ignored files left out)."""
    listed = git("ls-files", "-z", "--cached", "--others", "--exclude-standard", cwd=ROOT).split("\0")
    for rel in filter(None, listed):
        source = ROOT / rel
        if source.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, dest / rel)
    git("init", "-q", cwd=dest)
    git("add", "-A", cwd=dest)
    git("commit", "-q", "-m", "snapshot", cwd=dest)
    return dest


def test_bad_mesh_fails_the_hook_and_good_mesh_passes(tmp_path):
    hook_repo = snapshot(tmp_path / "hook-repo")
    work = tmp_path / "work"
    (work / "models").mkdir(parents=True)
    (work / "models" / "good.obj").write_text(quad_obj([(SQUARE, UNIT_UV)]))
    (work / "models" / "BAD.OBJ").write_text(quad_obj([(trapezoid(), UNIT_UV)]))
    (work / "notes.txt").write_text("not a mesh, never passed to the hook\n")
    git("init", "-q", cwd=work)
    git("add", "-A", cwd=work)
    env = {**os.environ, "PRE_COMMIT_HOME": str(tmp_path / "cache"), "PRE_COMMIT_COLOR": "never"}

    def try_repo(*files: str) -> subprocess.CompletedProcess:
        return subprocess.run(
            ["pre-commit", "try-repo", str(hook_repo), "affinity-check", "--verbose", "--files", *files],
            cwd=work, env=env, capture_output=True, text=True, timeout=600,
        )

    good = try_repo("models/good.obj", "notes.txt")
    assert good.returncode == 0, good.stdout + good.stderr
    assert "No findings (1 file checked)" in good.stdout

    bad = try_repo("models/good.obj", "models/BAD.OBJ")
    assert bad.returncode == 1, bad.stdout + bad.stderr
    assert "models/BAD.OBJ:9:1: Q101 uv-disaffine" in bad.stdout
    assert "Found 1 finding: 1 error (2 files checked)" in bad.stdout
