"""The pre-commit hook, run by the real ``pre-commit`` against a snapshot of this checkout.

A snapshot (every file git tracks or would track, as it is in the working tree)
committed to a temporary repository is the hook repository, so its revision equals
the working tree, uncommitted and untracked files included. An asset repository
names it in its ``.pre-commit-config.yaml`` as a user's would, and ``pre-commit
run`` installs the hook into a virtualenv once (the pre-commit cache lives in the
temporary folder, so the test is hermetic; ``try-repo`` would install it again for
every call, into a store of its own). Installing needs PyPI (setuptools, numpy)
and nothing else.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest
from helpers.quads import SQUARE, UNIT_UV, quad_obj, trapezoid

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
    revision = git("rev-parse", "HEAD", cwd=hook_repo).strip()
    work = tmp_path / "work"
    (work / "models").mkdir(parents=True)
    (work / "models" / "good.obj").write_text(quad_obj([(SQUARE, UNIT_UV)]))
    (work / "models" / "BAD.OBJ").write_text(quad_obj([(trapezoid(), UNIT_UV)]))
    (work / "notes.txt").write_text("not a mesh, never passed to the hook\n")
    (work / ".pre-commit-config.yaml").write_text(
        f"repos:\n  - repo: {hook_repo}\n    rev: {revision}\n    hooks:\n      - id: affinity-check\n")
    git("init", "-q", cwd=work)
    git("add", "-A", cwd=work)
    env = {**os.environ, "PRE_COMMIT_HOME": str(tmp_path / "cache"), "PRE_COMMIT_COLOR": "never"}

    def run_hook(*files: str) -> subprocess.CompletedProcess:
        return subprocess.run(
            ["pre-commit", "run", "affinity-check", "--verbose", "--files", *files],
            cwd=work, env=env, capture_output=True, text=True, timeout=600,
        )

    good = run_hook("models/good.obj", "notes.txt")
    assert good.returncode == 0, good.stdout + good.stderr
    assert "No findings (1 file checked)" in good.stdout

    bad = run_hook("models/good.obj", "models/BAD.OBJ")
    assert bad.returncode == 1, bad.stdout + bad.stderr
    assert "models/BAD.OBJ:9:1: Q101 error uv-disaffine" in bad.stdout
    assert "Found 1 finding: 1 error (2 files checked)" in bad.stdout
