"""Build the Blender extension zip: ``python -m affinity.blender.build -o dist/``.

Blender's own ``blender --command extension build`` needs the ``blender``
executable, which the ``bpy`` wheel does not have, so this does the same job in
Python. The zip holds

- ``blender_manifest.toml`` (schema 1.0.0, the format Blender 4.2+ installs),
- ``__init__.py``, which only re-exports ``register``/``unregister`` of
  :mod:`affinity.blender.addon`,
- ``wheels/quad_affinity-VERSION-py3-none-any.whl``, this project built by
  ``pip wheel``; Blender installs an extension's wheels when it enables it, so
  ``import affinity`` works inside Blender. NumPy comes with Blender.

Run it from a source checkout (it builds the wheel from the checkout's
``pyproject.toml``). Prints the zip's path.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
EXTENSION_ID = "quad_affinity"
#: What the wheel is built from (copied, so the build leaves no build/ or egg-info in the checkout).
SOURCES = ("pyproject.toml", "README.md", "affinity", "render")

INIT = '''"""Quad Affinity: lint quad meshes in Blender. The code is in the bundled quad-affinity wheel."""

from affinity.blender.addon import register, unregister

__all__ = ["register", "unregister"]
'''


def manifest(version: str, wheel: str) -> str:
    """The ``blender_manifest.toml`` text for this version and wheel file name."""
    return f'''schema_version = "1.0.0"

id = "{EXTENSION_ID}"
version = "{version}"
name = "Quad Affinity"
tagline = "Find quads whose UVs, colours or normals crease along the split"
maintainer = "quad-affinity developers"
type = "add-on"
tags = ["Mesh", "UV"]
blender_version_min = "4.2.0"
license = ["SPDX:MIT"]
wheels = ["./wheels/{wheel}"]

[permissions]
files = "Read the images that materials use (a UDIM image is saved to a temporary folder to read its tiles)"
'''


def build_wheel(out_dir: Path) -> Path:
    """Build the project's wheel into ``out_dir`` with ``pip wheel``; returns its path."""
    with tempfile.TemporaryDirectory() as tmp:
        source = Path(tmp) / "src"
        source.mkdir()
        ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
        for name in SOURCES:
            path = ROOT / name
            if path.is_dir():
                shutil.copytree(path, source / name, ignore=ignore)
            else:
                shutil.copy2(path, source / name)
        subprocess.run(
            [sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "--wheel-dir", str(out_dir), str(source)],
            check=True,
        )
    wheels = sorted(out_dir.glob("quad_affinity-*.whl"))
    if len(wheels) != 1:
        raise RuntimeError(f"expected one quad_affinity wheel in {out_dir}, found {len(wheels)}")
    return wheels[0]


def build(out_dir: str | os.PathLike) -> Path:
    """Write ``quad_affinity-VERSION.zip`` into ``out_dir`` (created if needed); returns its path."""
    pyproject = ROOT / "pyproject.toml"
    if not pyproject.is_file():
        raise SystemExit(f"affinity.blender.build: {pyproject} not found: run from a source checkout")
    version = tomllib.loads(pyproject.read_text())["project"]["version"]
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / f"{EXTENSION_ID}-{version}.zip"
    with tempfile.TemporaryDirectory() as tmp:
        wheel = build_wheel(Path(tmp))
        partial = target.with_suffix(".zip.partial")
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as archive:
            archive.writestr("blender_manifest.toml", manifest(version, wheel.name))
            archive.writestr("__init__.py", INIT)
            archive.write(wheel, f"wheels/{wheel.name}")
        os.replace(partial, target)  # never a half-written zip under the real name
    return target


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m affinity.blender.build", description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", default="dist", help="folder for the zip (default: dist)")
    args = parser.parse_args(argv)
    print(build(args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
