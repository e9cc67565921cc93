"""``affinity check`` on a 1,000,000-quad FBX against the OBJ of the same mesh, whole processes (issue 59).

The goal: an FBX checks within 1.5x the time of the OBJ of the same mesh. Both are written here from one
wavy grid (``bench_load.grid``: uv and normals for every vertex): the OBJ by ``bench_load.write_grid_obj``,
the FBX by the binary writer of tests/helpers/fbx_binary.py as Blender writes a mesh (``PolygonVertexIndex``,
uv and normals ``ByPolygonVertex``/``IndexToDirect``), once with its arrays zlib-compressed (as DCC tools
write them) and once raw. ufbx only reads, and Blender is not a dependency of the benchmarks.

Every case is ``affinity check --isolated --no-cache --format json FILE`` in a fresh process (interpreter
start, imports, load, every rule, output), bytecode cached as after a pip install; the cases take turns,
round after round, and the table gives the median and best wall time, the peak memory, and each FBX's
median over the OBJ's. Then the FBX read alone, in the forked reader and in the process itself, fresh
processes taking turns: the cost of reading where a crash costs one file.

    python benchmarks/bench_fbx.py                 # 1M quads in a temp dir, 5 rounds
    python benchmarks/bench_fbx.py --quads 100000 --rounds 3 --out /tmp/bench
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parent / "tests"), str(HERE)]

from bench_load import grid, run, write_grid_obj  # noqa: E402
from bench_startup import installed_env  # noqa: E402
from common import markdown_table, write_table  # noqa: E402

GOAL = 1.5
#: The FBX read alone in a fresh process: in the forked reader (as check reads it) or in the process itself.
READ = """
import sys, time
import numpy, ufbx
from affinity.loaders.fbxscene import read_fbx
from affinity.loaders.isolated import read_isolated
t = time.perf_counter()
if sys.argv[1] == "forked":
    read_isolated(sys.argv[2], read_fbx, sys.argv[2], None)
else:
    read_fbx(sys.argv[2])
print(time.perf_counter() - t)
"""


def read_costs(path: str, rounds: int) -> dict[str, float]:
    """Median seconds of reading ``path`` forked and in process, each in fresh processes taking turns."""
    seconds = {"forked": [], "in process": []}
    for _ in range(rounds):
        for how in seconds:
            seconds[how].append(float(run([sys.executable, "-c", READ, how.split()[0], path])[2]))
    return {how: statistics.median(values) for how, values in seconds.items()}


def write_grid_fbx(path: str, quads: int, compress: bool) -> None:
    """The mesh of :func:`bench_load.grid` as an FBX, uv and normals per corner through indices."""
    import numpy as np
    from helpers.fbx_binary import MeshNode, scene_bytes

    positions, uv, normals, faces = grid(quads)
    corners = faces.ravel()
    face_start = np.arange(0, 4 * len(faces) + 1, 4)
    mesh = MeshNode("Grid", positions, face_start, corners,
                    uv=[("UVMap", "ByPolygonVertex", "IndexToDirect", uv, corners)],
                    normals=("", "ByPolygonVertex", "IndexToDirect", normals, corners))
    Path(path).write_bytes(scene_bytes([mesh], unit_cm=100.0, compress=compress))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    parser.add_argument("--quads", type=int, default=1_000_000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--out", default=str(HERE.parent / "reports" / "bench"))
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as scratch:
        files = {"OBJ": os.path.join(scratch, "grid.obj"), "FBX, zlib arrays": os.path.join(scratch, "grid.fbx"),
                 "FBX, raw arrays": os.path.join(scratch, "grid_raw.fbx")}
        write_grid_obj(files["OBJ"], args.quads)
        write_grid_fbx(files["FBX, zlib arrays"], args.quads, compress=True)
        write_grid_fbx(files["FBX, raw arrays"], args.quads, compress=False)
        env = installed_env(os.path.join(scratch, "pycache"))
        os.environ.update(env)
        command = [sys.executable, "-m", "affinity.cli", "check", "--isolated", "--no-cache", "--format", "json"]
        load_before = os.getloadavg()[0]
        for path in files.values():  # one untimed run each: bytecode compiled, files in the page cache
            run([*command, path])
        times = {name: [] for name in files}
        for _ in range(args.rounds):
            for name, path in files.items():
                seconds, peak, _, code = run([*command, path])
                if code not in (0, 1):
                    sys.exit(f"bench_fbx: affinity check exited {code} on {path}")
                times[name].append((seconds, peak))
        costs = read_costs(files["FBX, zlib arrays"], args.rounds)
        load_after = os.getloadavg()[0]
        sizes = {name: os.path.getsize(path) / 1e6 for name, path in files.items()}
    obj = statistics.median(s for s, _ in times["OBJ"])
    rows = [[name, f"{sizes[name]:.0f} MB", f"{statistics.median(s for s, _ in runs):.2f} s",
             f"{min(s for s, _ in runs):.2f} s", f"{max(p for _, p in runs):.0f} MiB",
             f"{statistics.median(s for s, _ in runs) / obj:.2f}"] for name, runs in times.items()]
    lines = [f"`affinity check` on {args.quads:,} quads (uv and normals), whole processes, {args.rounds} rounds; "
             f"load average {load_before:.2f} before, {load_after:.2f} after.", "",
             *markdown_table(["file", "size", "median", "best", "peak RSS", "median / OBJ's"], rows), "",
             f"Goal: each FBX within {GOAL}x the OBJ. Reading the zlib FBX alone (fresh processes, median): "
             f"{costs['forked']:.2f} s in the forked reader, {costs['in process']:.2f} s in the process itself."]
    write_table(lines, Path(args.out), "bench_fbx.md")
    worst = max(statistics.median(s for s, _ in runs) / obj for name, runs in times.items() if name != "OBJ")
    if worst > GOAL:
        sys.exit(1)


if __name__ == "__main__":
    main()
