"""The report's lint: one pass giving the findings and every quad's scores, against a lint then a pass per score.

Issue 39: ``affinity report`` linted each mesh, then scored it again once per scored rule (the lint at a
threshold of -inf). Now one pass over the quads (``affinity.lint.lint_pass(..., scores=True)``) gives both.
This times, in one process with the two taking turns round after round, that pass against the lint followed
by one :func:`affinity.lint.quad_scores` pass per scored rule (the old number of passes), on a lat-long
sphere of 448 x 224 quads (100,352) carrying uv (its longitude and latitude), vertex colours (its positions
squared) and normals (its positions): all three scored rules measure every quad.

    python benchmarks/bench_lint_scores.py [--rounds 7] [--small] [--out reports/bench]

``--small`` makes 2 rounds on a 112 x 56 sphere. The table goes to ``OUT/bench_lint_scores.md``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from calibration import lat_long_sphere
from common import parse_with_output, run_conditions, write_table


def sphere_with_every_attribute(columns: int, rows: int):
    """The lat-long sphere loaded, with vertex colours (its positions squared) and unit normals (its positions)."""
    from affinity.loaders import load

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "sphere.obj"
        path.write_text(lat_long_sphere(columns, rows))
        mesh = load(str(path))
    return replace(mesh, colors=mesh.positions**2, normals=mesh.positions.copy(),
                   corner_normal=mesh.corner_vertex.copy())


def main(argv=None) -> None:
    from affinity.lint import lint_mesh, lint_pass, quad_scores, scored_codes
    from affinity.settings import Settings

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    args = parse_with_output(parser, "2 rounds on a 112 x 56 sphere", "folder for bench_lint_scores.md", argv)
    rounds, (columns, rows) = (2, (112, 56)) if args.small else (args.rounds, (448, 224))
    mesh = sphere_with_every_attribute(columns, rows)
    settings = Settings()
    codes = scored_codes(mesh)
    load = os.getloadavg()[0]

    def one_pass():
        return lint_pass(mesh, settings, scores=True).scores

    def lint_then_scores():
        lint_mesh(mesh, settings)
        return {code: quad_scores(mesh, settings, code) for code in codes}

    cases = {"one pass: findings and scores": one_pass, f"lint, then {len(codes)} score passes": lint_then_scores}
    seconds = {name: [] for name in cases}
    results = {}
    for _ in range(rounds):
        for name, run in cases.items():
            start = time.perf_counter()
            results[name] = run()
            seconds[name].append(time.perf_counter() - start)
    first, second = results.values()
    for code in codes:  # the same scores either way
        np.testing.assert_array_equal(first[code].faces, second[code].faces)
        np.testing.assert_allclose(first[code].values, second[code].values, rtol=1e-12)
    base = statistics.median(seconds[f"lint, then {len(codes)} score passes"])
    lines = [f"# The report's lint: {len(mesh.face_sizes):,} quads, scored by {', '.join(codes)}", "",
             run_conditions(load, rounds), "", "| case | median s | best s | ratio |", "|---|---:|---:|---:|"]
    for name, times in seconds.items():
        lines.append(f"| {name} | {statistics.median(times):.3f} | {min(times):.3f} | "
                     f"{statistics.median(times) / base:.2f} |")
    write_table(lines, args.out, "bench_lint_scores.md")


if __name__ == "__main__":
    main()
