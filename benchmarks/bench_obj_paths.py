"""The OBJ reader's fast and general paths, and this checkout against another, on three kinds of file.

Three files of ``--quads`` quads, each taking another path of :mod:`affinity.loaders.obj`:

- ``columns``: the bench grid (``%.6f`` numbers, ``v/vt/vn`` quads), lines laid out alike:
  the byte-column scan (:mod:`affinity.loaders.obj.alike`);
- ``blocks``: ``%g`` numbers (lines of differing lengths) and ``v/vt`` quads: tokens, read
  as one block per kind of line (the fast path of the vertex and face phases);
- ``general``: quads and triangles in turn, the triangles with a relative index: token by token.

Each file is read by ``load_obj`` (default: the fast path where it applies) and by
``load_obj(fast=False)`` (the general path for every chunk), each in a fresh process, the
cases taking turns round after round; with ``--against DIR`` also by the ``load_obj`` of the
checkout at DIR (say, the main branch), for a before/after ratio measured side by side. The
table gives the best wall and CPU seconds of the call (the process's start and imports left
out) and the CPU ratio to this checkout's default.

    python benchmarks/bench_obj_paths.py --against /work/main      # 250,000 quads, 5 rounds
    python benchmarks/bench_obj_paths.py --small --out /tmp/bench  # 5,000 quads, 1 round
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from bench_load import write_grid_obj
from common import ROOT, parse_with_output, write_table

#: Run in the child: read once (warm caches), then time one read; prints wall and CPU seconds.
CHILD = """import sys, time
from affinity.loaders.obj import load_obj
fast = sys.argv[2] == "fast"
load_obj(sys.argv[1], fast=fast)
wall, cpu = time.perf_counter(), time.process_time()
load_obj(sys.argv[1], fast=fast)
print(time.perf_counter() - wall, time.process_time() - cpu)
"""
#: The same for another checkout, whose ``load_obj`` may not have ``fast``.
CHILD_AGAINST = CHILD.replace("fast=fast", "")


def _grid(quads: int):
    """Corner indices (1-based) of an n x n grid's quads and the vertex (i, j) of each point."""
    n = int(np.ceil(np.sqrt(quads)))
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1))
    first = (j[:-1, :-1] * (n + 1) + i[:-1, :-1]).ravel() + 1
    return n, i.ravel(), j.ravel(), first


def write_blocks_obj(path: str, quads: int) -> None:
    """``%g`` positions and uv (lines of differing lengths), ``v/vt`` quads."""
    n, i, j, first = _grid(quads)
    x, y = i / 7.0, j / 3.0
    with open(path, "w") as out:
        out.writelines(f"v {a:g} {b:g} {np.sin(a):g}\n" for a, b in zip(x, y))
        out.writelines(f"vt {a / n:g} {b / n:g}\n" for a, b in zip(i, j))
        out.writelines(f"f {a}/{a} {a + 1}/{a + 1} {a + n + 2}/{a + n + 2} {a + n + 1}/{a + n + 1}\n" for a in first)


def write_general_obj(path: str, quads: int) -> None:
    """Integer positions; a quad and a triangle with a relative index in turn."""
    n, i, j, first = _grid(quads)
    with open(path, "w") as out:
        out.writelines(f"v {a} {b} 0\n" for a, b in zip(i, j))
        out.writelines(f"f {a} {a + 1} {a + n + 2} {a + n + 1}\nf {a} {a + 1} -1\n" for a in first)


WRITERS = {"columns": write_grid_obj, "blocks": write_blocks_obj, "general": write_general_obj}


def timed(path: str, tree: Path, child: str, *argv: str) -> tuple[float, float]:
    """(wall, CPU) seconds of one read of ``path`` in a fresh process importing ``tree``'s affinity."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    out = subprocess.run([sys.executable, "-c", child, path, *argv], env=env, capture_output=True, text=True,
                         check=True).stdout.split()
    return float(out[0]), float(out[1])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quads", type=int, default=250_000, help="quads in every file (default 250,000)")
    parser.add_argument("--rounds", type=int, default=5, help="reads of every case, taking turns (default 5)")
    parser.add_argument("--against", type=Path, help="another checkout whose load_obj reads the files too")
    args = parse_with_output(parser, "5,000 quads, one round", "folder of bench_obj_paths.md (reports/bench)", argv)
    if args.small:
        args.quads, args.rounds = 5_000, 1
    cases = {"fast (default)": (ROOT, CHILD, "fast"), "general (fast=False)": (ROOT, CHILD, "general")}
    if args.against:
        cases[f"default at {args.against}"] = (args.against, CHILD_AGAINST, "fast")
    load = os.getloadavg()[0]
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for kind, write in WRITERS.items():
            path = os.path.join(folder, f"{kind}.obj")
            write(path, args.quads)
            best = {case: (np.inf, np.inf) for case in cases}
            for _ in range(args.rounds):
                for case, (tree, child, mode) in cases.items():
                    wall, cpu = timed(path, tree, child, mode)
                    best[case] = (min(best[case][0], wall), min(best[case][1], cpu))
            base = best["fast (default)"][1]
            rows += [f"| {kind} | {case} | {wall:.3f} | {cpu:.3f} | {cpu / base:.2f} |"
                     for case, (wall, cpu) in best.items()]
    lines = [f"`load_obj` on {args.quads:,} quads per file; {platform.processor() or platform.machine()}, "
             f"{os.cpu_count()} CPUs, load {load:.2f} before; best of {args.rounds} round{'s' * (args.rounds > 1)}, "
             "every read a fresh process, the cases taking turns.", "",
             "| file | path | best wall s | best CPU s | CPU / fast |", "|---|---|---:|---:|---:|", *rows]
    write_table(lines, args.out, "bench_obj_paths.md")


if __name__ == "__main__":
    main()
