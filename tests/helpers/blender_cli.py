"""The command line's side of the Blender tests: ``affinity`` run by a Python that has Pillow.

The Blender tests run in the bpy venv, which has no Pillow (as Blender ships none); the command line
decodes textures with Pillow, so it runs in another Python: ``AFFINITY_CLI_PYTHON``, else the CI's main
venv ``.venv-ci/bin/python`` (.ci/run builds it before the Blender leg). A test skips, naming why, only
where neither exists.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def cli_python() -> str:
    """A Python with Pillow to run this checkout's command line, or a skip saying why there is none."""
    for python in filter(None, [os.environ.get("AFFINITY_CLI_PYTHON"), str(ROOT / ".venv-ci" / "bin" / "python")]):
        if Path(python).is_file():
            return python
    pytest.skip("no Python with Pillow for the command line's side: set AFFINITY_CLI_PYTHON or build .venv-ci "
                "(.ci/run does, before the Blender leg)")


def run_cli_json(*args: str) -> dict:
    """The JSON of ``affinity ARGS --format json`` run on this checkout by :func:`cli_python` (exit 0 or 1)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    result = subprocess.run([cli_python(), "-m", "affinity.cli", *args, "--format", "json"], capture_output=True,
                            text=True, env=env, timeout=600, check=False)
    assert result.returncode in (0, 1), result.stderr
    return json.loads(result.stdout)
