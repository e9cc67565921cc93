"""The Open Chess Set fixed two ways: ``affinity fix`` and the validators' ``RefineQuads`` fixer (issue 55).

Both write shared geometry once (:func:`affinity.fix.usdlayer.write_refined`). ``affinity fix`` is timed as a
process; the fixer as its apply phase: a process opens an override layer that sublayers the stage, validates
it (not timed), then asks every error's fixers whether they apply and applies them (timed) and saves the layer.
The table gives both times, the layers' sizes and how many prim specs author ``points`` in each.

    python benchmarks/bench_usd_fixer.py [--out reports/bench]

Not a test: run it once and read it (it takes minutes on the 400k-face set).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

from bench_startup import affinity_command
from common import ROOT, parse_with_output, run_conditions, write_table

STAGE = ROOT.parent / "shared" / "meshes" / "usd" / "OpenChessSet" / "chess_set.usda"

#: Validates argv[1] (an override layer), then times the fixers of its errors and saves the layer.
FIXER = textwrap.dedent('''
    import sys, time
    from pxr import Usd, UsdValidation
    stage = Usd.Stage.Open(sys.argv[1])
    errors = UsdValidation.ValidationContext(["quad-affinity"], True).Validate(stage)
    target = Usd.EditTarget(stage.GetRootLayer())
    start = time.perf_counter()
    applied = 0
    for error in errors:
        for fixer in error.GetFixers():
            if fixer.CanApplyFix(error, target):
                applied += fixer.ApplyFix(error, target)
    stage.GetRootLayer().Save()
    print(len(errors), applied, time.perf_counter() - start)
''')


def points_specs(path: str) -> int:
    """Prim specs of the layer at ``path`` that author ``points``."""
    from pxr import Sdf

    layer = Sdf.Layer.FindOrOpen(path)
    found = []
    layer.Traverse(layer.pseudoRoot.path, lambda spec: found.append(spec)
                   if spec.IsPropertyPath() and spec.name == "points" else None)
    return len(found)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args = parse_with_output(parser, "(no smaller run: the chess set is the case)", "folder for bench_usd_fixer.md")
    if not STAGE.is_file():
        raise SystemExit(f"{STAGE} is absent")
    load = os.getloadavg()[0]
    plugin = subprocess.run([*affinity_command(), "usd-plugin"], capture_output=True, text=True, check=True)
    env = {**os.environ, "PXR_PLUGINPATH_NAME": plugin.stdout.strip(),
           "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    with tempfile.TemporaryDirectory() as tmp:
        fixed = os.path.join(tmp, "chess_set.fixed.usda")
        start = time.perf_counter()
        subprocess.run([*affinity_command(), "fix", "-q", "-o", fixed, str(STAGE)], check=False, env=env,
                       capture_output=True)
        fix_seconds = time.perf_counter() - start
        override = os.path.join(tmp, "override.usda")
        Path(override).write_text(f"#usda 1.0\n(\n    subLayers = [@{STAGE}@]\n)\n")
        result = subprocess.run([sys.executable, "-c", FIXER, override], capture_output=True, text=True, env=env,
                                check=True)
        errors, applied, fixer_seconds = result.stdout.split()
        sizes = {name: (os.path.getsize(path), points_specs(path)) for name, path in
                 (("affinity fix", fixed), ("RefineQuads fixer", override))}
    lines = [
        f"The Open Chess Set ({STAGE.name}, 400,798 faces): {run_conditions(load, 1)}.",
        "",
        "| case | seconds | / affinity fix | layer bytes (usda) | prim specs with points |",
        "|---|---:|---:|---:|---:|",
        f"| `affinity fix` (process) | {fix_seconds:.1f} | 1.00 | {sizes['affinity fix'][0]:,} | "
        f"{sizes['affinity fix'][1]} |",
        f"| RefineQuads fixer: {applied} of {errors} errors applied (apply phase) | {float(fixer_seconds):.1f} | "
        f"{float(fixer_seconds) / fix_seconds:.2f} | {sizes['RefineQuads fixer'][0]:,} | "
        f"{sizes['RefineQuads fixer'][1]} |",
    ]
    write_table(lines, args.out, "bench_usd_fixer.md")


if __name__ == "__main__":
    main()
