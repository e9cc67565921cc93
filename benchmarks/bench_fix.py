"""``affinity fix`` on a 100k-quad mesh: wall time and peak memory, beside ``affinity check`` on the same file.

The mesh is made as ``../shared/meshes/gen_spot_cc4.obj`` is made from Spot, by the shared
folder's own ``reproduce.py``: the OpenSubdiv car (``osd_catmark_car.obj``, 1,575 quads with
per-face unit uv) subdivided three times with Catmull-Clark positions and face-varying linear
uv: 100,800 quads. Each round runs, in fresh processes, ``affinity check``, ``affinity fix
--dry-run`` and ``affinity fix`` (which writes ``car.fixed.obj``), one after the other, so the
ratios compare runs made side by side under the same load.

    python benchmarks/bench_fix.py                       # 100,800 quads, 3 rounds
    python benchmarks/bench_fix.py --small --out /tmp/b  # 6,300 quads (two subdivisions), 1 round

Without the shared meshes, ``--small`` runs on the bundled demo sphere instead (a smoke run: the
figures then say so); the full run needs the car.

The table goes to ``<out>/bench_fix.md`` (default ``reports/bench/``).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np
from bench_report import timed_process
from common import markdown_table, parse_with_output, run_conditions, write_table

SHARED = Path(__file__).resolve().parents[2] / "shared" / "meshes"
CAR = SHARED / "osd_catmark_car.obj"
DEMO_SPHERE = Path(__file__).resolve().parents[1] / "affinity" / "data" / "demo" / "sphere.obj"


def write_subdivided_car(path: str, levels: int) -> int:
    """Write the car after ``levels`` Catmull-Clark steps (``reproduce.catmull_clark``) to ``path``; its quads."""
    spec = importlib.util.spec_from_file_location("reproduce", SHARED / "reproduce.py")
    reproduce = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(reproduce)
    V, VT, F, FT = reproduce.read_obj_poly(str(CAR))
    for _ in range(levels):
        V, F, VT, FT = reproduce.catmull_clark(V, F, VT, FT)
    quads, uv = np.asarray(F, dtype=np.int64), np.asarray(FT, dtype=np.int64)
    with open(path, "w") as out:
        np.savetxt(out, V, fmt="v %.9g %.9g %.9g")
        np.savetxt(out, VT, fmt="vt %.9g %.9g")
        np.savetxt(out, np.stack([quads + 1, uv + 1], axis=2).reshape(-1, 8), fmt="f" + " %d/%d" * 4)
    return len(quads)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parse_with_output(parser, "6,300 quads, 1 round", "folder of bench_fix.md", argv)
    if not CAR.exists() and not args.small:
        sys.exit(f"{CAR} is absent: this benchmark needs the shared meshes")
    levels, rounds = (2, 1) if args.small else (3, args.rounds)
    python = [sys.executable, "-m", "affinity.cli"]
    with tempfile.TemporaryDirectory() as folder:
        mesh = os.path.join(folder, "car.obj")
        if CAR.exists():
            quads = write_subdivided_car(mesh, levels)
            source = f"the shared car, Catmull-Clark x{levels}, face-varying linear uv"
        else:
            shutil.copyfile(DEMO_SPHERE, mesh)
            quads, source = 128, "the demo sphere: no shared car here"
        load = os.getloadavg()[0]
        commands = {
            "`affinity check`": [*python, "check", "-q", "--isolated", "--no-cache", mesh],
            "`affinity fix --dry-run`": [*python, "fix", "-q", "--isolated", "--dry-run", mesh],
            "`affinity fix`": [*python, "fix", "-q", "--isolated", mesh],
        }
        runs = {name: [] for name in commands}
        for _ in range(rounds):
            for name, command in commands.items():
                runs[name].append(timed_process(command, ok=(0, 1)))
        summary = runs["`affinity fix`"][-1][2].strip().splitlines()[-1].split(": ", 1)[-1]
        written = os.path.getsize(os.path.join(folder, "car.fixed.obj")) / 2**20
    check = statistics.median(run[0] for run in runs["`affinity check`"])
    rows = [(name, f"{statistics.median(r[0] for r in found):.2f}",
             f"{statistics.median(r[0] for r in found) / check:.2f}", f"{max(r[1] for r in found):.0f}")
            for name, found in runs.items()]
    write_table([
        f"{quads:,} quads ({source}), "
        f"{run_conditions(load, rounds)}, each command in a fresh process:",
        "",
        *markdown_table(["command", "wall (s)", "x check", "peak memory (MiB)"], rows),
        "",
        f"The fix: {summary.split(' -> ')[0]}; the fixed OBJ is {written:.1f} MiB.",
    ], args.out, "bench_fix.md")


if __name__ == "__main__":
    main()
