"""``affinity report`` on a car-sized mesh: the whole command's wall time and peak memory, and the UV layout's share.

The mesh is the shared OpenSubdiv car (``../shared/meshes/osd_catmark_car.obj``,
1,575 quads with per-face unit uv) subdivided linearly three times: 100,800 quads,
every one of them mapping the whole texture square, as the issue's car did. When
the shared meshes are absent the built-in demo sphere is subdivided instead (said
in the table). Each round runs ``affinity report -q`` in a fresh process; the UV
layout (:func:`affinity.report.uvlayout.layout_image` and its SVG) is timed in one
more process on the same file and the lint's flags. Without ``--small``, each
mesh of ``../shared/meshes`` is then reported once the same way (wall time and peak
memory), so the README can say what the report costs on real assets.

    python benchmarks/bench_report.py                 # 100,800 quads, 3 rounds
    python benchmarks/bench_report.py --small --out /tmp/bench   # 6,300 quads, 1 round (the test's case)

The table goes to ``<out>/bench_report.md`` (default ``reports/bench/``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from common import markdown_table, parse_with_output, run_conditions, write_table

SHARED = Path(__file__).resolve().parents[2] / "shared" / "meshes"
CAR = SHARED / "osd_catmark_car.obj"
LAYOUT_CHILD = """
import sys, time
import numpy as np
from affinity.pipeline.check import load_and_check
from affinity.report.uvlayout import LAYOUT_SIZE, layout_image, layout_svg
from affinity.settings import Settings
file, mesh = load_and_check(sys.argv[1], Settings())
flagged = np.zeros(mesh.n_faces, dtype=bool)
for hits in file.hits:
    flagged[hits.faces[hits.faces >= 0]] = True
start = time.perf_counter()
layout_svg(mesh, layout_image(mesh, flagged, LAYOUT_SIZE), [])
print(time.perf_counter() - start)
"""


def subdivide(positions: np.ndarray, quads: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One linear subdivision: each quad (Q, 4) int64 into four, edge midpoints shared between neighbours.

    Returns the positions (V + E + Q, 3) float64 and the quads (4Q, 4) int64, wound as their parents.
    """
    edges = np.sort(np.stack([quads, np.roll(quads, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
    unique, edge = np.unique(edges, axis=0, return_inverse=True)
    mid = len(positions) + edge.reshape(-1, 4)
    centre = len(positions) + len(unique) + np.arange(len(quads))
    positions = np.concatenate([positions, positions[unique].mean(axis=1), positions[quads].mean(axis=1)])
    (a, b, c, d), (ab, bc, cd, da) = quads.T, mid.T
    children = [(a, ab, centre, da), (ab, b, bc, centre), (centre, bc, c, cd), (da, centre, cd, d)]
    return positions, np.stack([np.stack(child, axis=1) for child in children], axis=1).reshape(-1, 4)


def write_car(path: str, levels: int) -> tuple[str, int]:
    """Write the subdivided car (or demo sphere) with per-face unit uv to ``path``; return what it came from
    and its quads."""
    from affinity.loaders import load
    from affinity.scenes import DEMO_SPHERE

    source = load(str(CAR)) if CAR.exists() else DEMO_SPHERE.mesh()
    positions, quads = source.positions, source.corner_vertex.reshape(-1, 4)
    for _ in range(levels):
        positions, quads = subdivide(positions, quads)
    with open(path, "w") as out:
        np.savetxt(out, positions, fmt="v %.6f %.6f %.6f")
        out.write("vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n")
        corners = np.stack([quads + 1, np.tile(np.arange(1, 5), (len(quads), 1))], axis=2).reshape(-1, 8)
        np.savetxt(out, corners, fmt="f" + " %d/%d" * 4)
    origin = "the shared car" if CAR.exists() else "the demo sphere (no shared car)"
    return f"{origin}, subdivided {levels}x", len(quads)


def timed_process(command: list[str], ok: tuple[int, ...] = (0,)) -> tuple[float, float, str]:
    """Run ``command`` (whose output is a few lines); its wall time (s), peak resident memory (MiB), stdout.
    An exit code outside ``ok`` stops the benchmark."""
    start = time.perf_counter()
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    child.returncode = os.waitstatus_to_exitcode(status)
    out, err = child.stdout.read(), child.stderr.read()
    child.stdout.close(), child.stderr.close()
    if child.returncode not in ok:
        sys.exit(f"{' '.join(command)} failed:\n{err}")
    return wall, usage.ru_maxrss / 1024, out


def car_options(doc: str, rounds: int, table: str, argv=None) -> tuple[argparse.Namespace, int, int]:
    """A benchmark on the subdivided car: its options (``--rounds``, default ``rounds``; ``--small``, 6,300
    quads and one round; ``--out``, the folder of ``table``), the car's subdivision levels and the rounds."""
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=rounds)
    args = parse_with_output(parser, "6,300 quads, 1 round", f"folder of {table}", argv)
    return args, *((1, 1) if args.small else (3, args.rounds))


def main(argv=None) -> None:
    args, levels, rounds = car_options(__doc__, 3, "bench_report.md", argv)
    with tempfile.TemporaryDirectory() as folder:
        mesh = os.path.join(folder, "car.obj")
        source, quads = write_car(mesh, levels)
        load = os.getloadavg()[0]
        runs = [timed_process([sys.executable, "-m", "affinity.cli", "report", "-q", mesh,
                               "-o", os.path.join(folder, "report.html")]) for _ in range(rounds)]
        layout = float(timed_process([sys.executable, "-c", LAYOUT_CHILD, mesh])[2])
        shared = [] if args.small else [
            (path.name, *timed_process([sys.executable, "-m", "affinity.cli", "report", "-q", str(path),
                                        "-o", os.path.join(folder, "shared.html")])[:2])
            for path in sorted(SHARED.glob("*.obj"))]
    wall = statistics.median(run[0] for run in runs)
    memory = max(run[1] for run in runs)
    shared_table = ["", "The meshes of `../shared/meshes`, one `affinity report -q` each:", "",
                    *markdown_table(["mesh", "wall (s)", "peak memory (MiB)"],
                                    [(name, f"{seconds:.2f}", f"{peak:.0f}") for name, seconds, peak in shared])
                    ] if shared else []
    write_table([
        f"{quads:,} quads ({source}, per-face unit uv), {run_conditions(load, rounds)}:",
        "",
        *markdown_table(
            ["`affinity report -q`", "wall (s)", "peak memory (MiB)", "UV layout (s)", "UV layout share"],
            [(f"{quads:,} quads", f"{wall:.2f}", f"{memory:.0f}", f"{layout:.2f}", f"{layout / wall:.1%}")]),
        *shared_table,
    ], args.out, "bench_report.md")


if __name__ == "__main__":
    main()
