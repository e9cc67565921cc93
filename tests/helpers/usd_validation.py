"""The UsdValidation validators run as a USD application runs them: a fresh process told about the plug-in by
``affinity usd-plugin`` (tests/test_usd_validators.py, tests/test_fix_usd_shared.py)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

from helpers.cli import run

VALIDATE = textwrap.dedent('''
    import json, sys
    from pxr import Usd, UsdValidation
    stage = Usd.Stage.Open(sys.argv[1])
    context = UsdValidation.ValidationContext(["quad-affinity"], True)
    errors = context.Validate(stage)
    if "--fix" in sys.argv:
        target = Usd.EditTarget(stage.GetRootLayer())
        for error in errors:
            for fixer in error.GetFixers():
                if fixer.CanApplyFix(error, target):
                    assert fixer.ApplyFix(error, target), error.GetMessage()
        errors = context.Validate(stage)
    for error in errors:
        print(json.dumps({
            "validator": error.GetValidator().GetMetadata().name, "name": error.GetName(),
            "type": str(error.GetType()).rsplit(".", 1)[-1], "message": error.GetMessage(),
            "prims": [str(site.GetPrim().GetPath()) for site in error.GetSites() if site.GetPrim()],
            "layers": [site.GetLayer().realPath for site in error.GetSites() if site.GetLayer()],
            "fixers": [fixer.name for fixer in error.GetFixers()]}))
''')


def plugin_env() -> dict:
    """The environment of a USD application told about the plug-in by ``affinity usd-plugin``."""
    result = run("usd-plugin")
    assert result.returncode == 0, result.stderr
    folder = result.stdout.strip()
    return {**os.environ, "PXR_PLUGINPATH_NAME": os.pathsep.join(filter(None, [folder,
                                                                              os.environ.get("PXR_PLUGINPATH_NAME")]))}


def validate(stage: Path, *flags: str) -> list[dict]:
    result = subprocess.run([sys.executable, "-c", VALIDATE, str(stage), *flags], capture_output=True, text=True,
                            env=plugin_env(), timeout=300, cwd=stage.parent)
    assert result.returncode == 0, result.stderr
    return [json.loads(line) for line in result.stdout.splitlines()]
