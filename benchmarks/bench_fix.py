"""``affinity fix`` on a 100k-quad mesh: wall time and peak memory, beside ``affinity check`` on the same file.

The mesh is made as ``../shared/meshes/gen_spot_cc4.obj`` is made from Spot, by the shared
folder's own ``reproduce.py``: the OpenSubdiv car (``osd_catmark_car.obj``, 1,575 quads with
per-face unit uv) subdivided three times with Catmull-Clark positions and face-varying linear
uv: 100,800 quads. Each round runs, in fresh processes, ``affinity check``, ``affinity fix
--dry-run`` and ``affinity fix`` (which writes ``car.fixed.obj``), one after the other, so the
ratios compare runs made side by side under the same load.

    python benchmarks/bench_fix.py                       # 100,800 quads, 3 rounds
    python benchmarks/bench_fix.py --small --out /tmp/b  # 6,300 quads (two subdivisions), 1 round
    python benchmarks/bench_fix.py --million             # the output budget on 1,000,000 quads, 1 round

Without the shared meshes, ``--small`` runs on the bundled demo sphere instead (a smoke run: the
figures then say so); the full run needs the car. The fixed car is read back: its faces by corner
count (the fix keeps quads) and its growth.

``--million`` writes 1,000 rows of 1,000 trapezoids (rows alternately widening and narrowing, the uv
a regular grid spanning 31-154 texels a quad at the assumed 1024 px), whose quads need n = 5-9, and
runs ``affinity fix`` once: its wall time, peak memory and what the budget left ``over-budget``.

The table goes to ``<out>/bench_fix.md`` (``bench_fix_million.md`` with ``--million``; default
``reports/bench/``).
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


def write_trapezoid_rows(path: str, columns: int, rows: int, spread=(0.03, 0.15)) -> int:
    """Write ``rows`` x ``columns`` quads: row j's vertices x-spaced 1 or 2 (alternately) times the uv's, so
    every quad is a trapezoid carrying a square of uv; the uv step grows along x over ``spread``. Its quads."""
    step = np.linspace(*spread, columns)
    u = np.concatenate([[0.0], np.cumsum(step)])
    width = np.where(np.arange(rows + 1) % 2, 2.0, 1.0)
    x = u[None, :] / step.mean() * width[:, None]
    y = np.repeat(np.arange(rows + 1.0)[:, None], columns + 1, axis=1)
    j, i = np.divmod(np.arange(columns * rows), columns)
    first = j * (columns + 1) + i + 1
    quads = np.stack([first, first + 1, first + columns + 2, first + columns + 1], axis=1)
    with open(path, "w") as out:
        np.savetxt(out, np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1), fmt="v %.9g %.9g %.9g")
        np.savetxt(out, np.stack([np.broadcast_to(u, x.shape).ravel(), y.ravel() * step.mean()], axis=1),
                   fmt="vt %.9g %.9g")
        np.savetxt(out, np.repeat(quads, 2, axis=1), fmt="f" + " %d/%d" * 4)
    return len(quads)


def faces_by_corners(path: str) -> dict[int, int]:
    """How many faces of the OBJ at ``path`` have each number of corners."""
    from affinity.loaders import load

    sizes, counts = np.unique(load(path).face_sizes, return_counts=True)
    return dict(zip(sizes.tolist(), counts.tolist()))


def million(args) -> None:
    """The output budget on 1,000,000 quads that need n = 5-9 (module docstring)."""
    python = [sys.executable, "-m", "affinity.cli"]
    with tempfile.TemporaryDirectory() as folder:
        mesh = os.path.join(folder, "rows.obj")
        quads = write_trapezoid_rows(mesh, 1000, 1000)
        load = os.getloadavg()[0]
        wall, peak, out = timed_process([*python, "fix", "-q", "--isolated", mesh], ok=(1,))
        summary = out.strip().splitlines()[-1].split(": ", 1)[-1]
        written = os.path.getsize(os.path.join(folder, "rows.fixed.obj")) / 2**20
        source = os.path.getsize(mesh) / 2**20
    write_table([
        f"{quads:,} quads (trapezoid rows needing n = 5-9, {source:.0f} MiB), {run_conditions(load, 1)}, "
        "`affinity fix` at its default budget in a fresh process:",
        "",
        *markdown_table(["wall (s)", "peak memory (MiB)", "fixed OBJ (MiB)"],
                        [(f"{wall:.1f}", f"{peak:.0f}", f"{written:.0f}")]),
        "",
        f"The fix: {summary.split(' -> ')[0]}.",
    ], args.out, "bench_fix_million.md")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--million", action="store_true", help="the output budget on 1,000,000 quads")
    args = parse_with_output(parser, "6,300 quads, 1 round", "folder of bench_fix.md", argv)
    if args.million:
        million(args)
        return
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
        source_size = os.path.getsize(mesh) / 2**20
        corners = faces_by_corners(os.path.join(folder, "car.fixed.obj"))
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
        f"The fix: {summary.split(' -> ')[0]}; the fixed OBJ is {written:.1f} MiB ({written / source_size:.1f}x "
        f"the input); its faces by corners: " + ", ".join(f"{k}: {v:,}" for k, v in sorted(corners.items())) + ".",
    ], args.out, "bench_fix.md")


if __name__ == "__main__":
    main()
