"""Q101 where the renderer draws it: ``affinity check``'s lint at subdivision levels 1 and 2 against the cage.

Issue 56: at level L the lint refines the mesh (affinity.subdivision, NumPy) and measures the 4^L refined
quads of every base face, so its cost should grow about as the refined quads do; the goal is at most
2 x 4^L the cage's time. This times :func:`affinity.lint.lint_pass` (Q101 and Q106, uv from the lat-long
sphere's longitude and latitude) on a sphere of 448 x 224 quads (100,352), the cage and levels 1 and 2
taking turns round after round, and records each one's peak of traced memory (tracemalloc, NumPy's arrays
included) in a round of its own.

    python benchmarks/bench_subdivision.py [--rounds 3] [--small] [--out reports/bench]

``--small`` makes 1 round on a 56 x 28 sphere. The table goes to ``OUT/bench_subdivision.md``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
import tracemalloc
from pathlib import Path

from calibration import lat_long_sphere
from common import markdown_table, parse_with_output, run_conditions, write_table

LEVELS = ("cage", "level:1", "level:2")


def main(argv=None) -> None:
    from affinity.lint import lint_pass
    from affinity.loaders import load
    from affinity.settings import Settings

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parse_with_output(parser, "1 round on a 56 x 28 sphere", "folder of the table", argv)
    columns, rows, rounds = (56, 28, 1) if args.small else (448, 224, args.rounds)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "sphere.obj"
        path.write_text(lat_long_sphere(columns, rows))
        mesh = load(str(path))
    settings = {level: Settings(select=["Q101", "Q106"], subdivision=level) for level in LEVELS}
    load_before = os.getloadavg()[0]
    times = {level: [] for level in LEVELS}
    for _ in range(rounds):
        for level in LEVELS:
            start = time.perf_counter()
            lint_pass(mesh, settings[level], visible=False)
            times[level].append(time.perf_counter() - start)
    peaks = {}
    for level in LEVELS:
        tracemalloc.start()
        lint_pass(mesh, settings[level], visible=False)
        peaks[level] = tracemalloc.get_traced_memory()[1] / 2**20
        tracemalloc.stop()
    cage = statistics.median(times["cage"])
    table = []
    for level in LEVELS:
        median = statistics.median(times[level])
        goal = "-" if level == "cage" else f"{2 * 4 ** int(level.split(':')[1])}"
        table.append([level, f"{median:.2f}", f"{median / cage:.1f}", goal, f"{peaks[level]:.0f}"])
    lines = [f"Lint of {mesh.n_faces:,} quads (Q101 and Q106) by subdivision level: "
             f"{run_conditions(load_before, rounds)}.",
             "", *markdown_table(["subdivision", "seconds", "x cage", "goal (x cage)", "peak MiB"], table)]
    write_table(lines, args.out, "bench_subdivision.md")


if __name__ == "__main__":
    main()
