"""Each rule's lint on Q quads with uv, colours and normals, in this tree and another, side by side.

Issue 39 made the checks pure measures (Q103 no longer reads its threshold to skip the arctangent
of the quads below it) behind one signature. This times ``lint_mesh`` with one rule selected, at
the rule's default threshold, in a fresh process per tree and round, the trees taking turns:

    python benchmarks/bench_rule_checks.py --base /path/to/other/tree [--quads 1000000] [--rounds 3]

Without ``--base`` the tree is timed against itself: the noise between two runs. ``--small``: 20,000
quads, one round. Not a test: run it and read it.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import textwrap
import time
from pathlib import Path

from common import ROOT, parse_with_output, run_conditions, write_table

CODES = ["Q101", "Q102", "Q103", "Q201", "Q202", "Q203", "Q204", "Q301", "Q302"]

#: Prints "CODE seconds" per rule: the best of three lints of a jittered grid of argv[1] quads.
TIMING = textwrap.dedent('''
    import sys, time
    import numpy as np
    from affinity.lint import lint_mesh
    from affinity.mesh import Mesh
    from affinity.settings import Settings

    n = int(int(sys.argv[1]) ** 0.5)
    rng = np.random.default_rng(39)
    grid = np.stack(np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0)), axis=-1).reshape(-1, 2)
    positions = np.column_stack([grid + rng.uniform(-0.2, 0.2, grid.shape), rng.uniform(-0.1, 0.1, len(grid))])
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    v0 = (j * (n + 1) + i).ravel()
    corners = np.stack([v0, v0 + 1, v0 + n + 2, v0 + n + 1], axis=1).ravel()
    q = n * n
    normals = np.column_stack([rng.uniform(-0.3, 0.3, (len(grid), 2)), np.ones(len(grid))])
    mesh = Mesh(path="grid.obj", positions=positions, face_start=np.arange(0, 4 * q + 1, 4), corner_vertex=corners,
                texcoords=grid / n, corner_texcoord=corners, colors=rng.uniform(0, 1, (len(grid), 3)),
                normals=normals, corner_normal=corners, face_line=np.arange(1, q + 1))
    for code in sys.argv[2:]:
        settings = Settings(select=[code])
        seconds = []
        for _ in range(3):
            start = time.perf_counter()
            lint_mesh(mesh, settings, visible=False)
            seconds.append(time.perf_counter() - start)
        print(code, min(seconds))
''')


def timings(tree: Path, quads: int) -> dict[str, float]:
    """Rule code -> seconds of its lint, in a fresh process importing ``tree``'s affinity."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    out = subprocess.run([sys.executable, "-c", TIMING, str(quads), *CODES], env=env, capture_output=True,
                         text=True, check=True).stdout
    return {code: float(seconds) for code, seconds in (line.split() for line in out.splitlines())}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", type=Path, default=ROOT,
                        help="the other tree, e.g. an export of main (default: this one, the noise)")
    parser.add_argument("--quads", type=int, default=1_000_000)
    parser.add_argument("--rounds", type=int, default=3)
    args = parse_with_output(parser, "20,000 quads, one round", "folder of the table", argv)
    quads, rounds = (20_000, 1) if args.small else (args.quads, args.rounds)
    load = os.getloadavg()[0]
    runs: dict[str, list[dict[str, float]]] = {"base": [], "this": []}
    for _ in range(rounds):
        runs["base"].append(timings(args.base, quads))
        runs["this"].append(timings(ROOT, quads))
    median = {tree: {code: statistics.median(r[code] for r in rounds_) for code in CODES}
              for tree, rounds_ in runs.items()}
    lines = [f"Rule checks on {quads:,} quads (lint_mesh, one rule selected, best of 3 in a process), base "
             f"{args.base}; {run_conditions(load, rounds)}; {time.strftime('%Y-%m-%d')}", "",
             "| rule | base (s) | this tree (s) | this / base |", "|---|---:|---:|---:|"]
    for code in CODES:
        base, this = median["base"][code], median["this"][code]
        lines.append(f"| {code} | {base:.3f} | {this:.3f} | {this / base:.2f} |")
    write_table(lines, args.out, Path(__file__).with_suffix(".md").name)


if __name__ == "__main__":
    main()
