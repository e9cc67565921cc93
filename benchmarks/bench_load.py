"""Loader speed and memory against the whole CLI and other readers, on one big OBJ.

Generates (once) an OBJ of ``--quads`` quads on a wavy grid with ``vt`` and ``vn``
for every vertex (1,000,000 quads: about 166 MB), then runs every case in a
fresh process and reports the time of the call itself, the wall time of the
whole process (interpreter start and imports included) and its peak resident
memory. Cases whose tool is missing print "n/a".

    python benchmarks/bench_load.py                 # 1M quads in a temp dir
    python benchmarks/bench_load.py --quads 200000 --path /tmp/grid.obj
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

#: name -> (module that must be importable, Python statement timed inside the child)
READERS = {
    "affinity.loaders.load": ("affinity.loaders", "import affinity.loaders as m; call = lambda p: m.load(p)"),
    "trimesh.load(process=False)": ("trimesh", "import trimesh as m; call = lambda p: m.load(p, process=False)"),
    "pyvista.read": ("pyvista", "import pyvista as m; call = lambda p: m.read(p)"),
}
CHILD = "import sys, time\n{setup}\nt = time.perf_counter(); call(sys.argv[1]); print(time.perf_counter() - t)\n"


def grid(quads: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``quads`` quads on an n x m wavy grid: positions (V, 3), uv (V, 2) and normals (V, 3) float64 per
    vertex, and faces (quads, 4) int64, 0-based."""
    n = int(np.ceil(np.sqrt(quads)))
    m = -(-quads // n)
    i, j = np.meshgrid(np.arange(n + 1), np.arange(m + 1))
    u, v = (i / n).ravel(), (j / m).ravel()
    positions = np.stack([10 * u - 5, 10 * v - 5, 0.3 * np.sin(7 * u) * np.cos(5 * v)], axis=1)
    normals = np.stack([np.zeros_like(u), np.sin(v), np.cos(v)], axis=1)
    corner = (j[:-1, :-1] * (n + 1) + i[:-1, :-1]).ravel()[:quads]
    faces = np.stack([corner, corner + 1, corner + n + 2, corner + n + 1], axis=1)
    return positions, np.stack([u, v], axis=1), normals, faces


def write_grid_obj(path: str, quads: int) -> None:
    """Write an OBJ with ``quads`` quads on an n x m grid (:func:`grid`), one vt and one vn per vertex."""
    positions, uv, normals, faces = grid(quads)
    with open(path, "w") as fh:
        fh.write(f"# {quads} quads, written by benchmarks/bench_load.py\n")
        np.savetxt(fh, positions, fmt="v %.6f %.6f %.6f")
        np.savetxt(fh, uv, fmt="vt %.6f %.6f")
        np.savetxt(fh, normals, fmt="vn %.6f %.6f %.6f")
        np.savetxt(fh, np.repeat(faces + 1, 3, axis=1), fmt="f" + " %d/%d/%d" * 4)


def generated_input(path: str, quads: int, write) -> str:
    """``path``, first written by ``write(path, quads)`` when it does not exist; prints its size."""
    if not os.path.exists(path):
        start = time.perf_counter()
        write(path, quads)
        print(f"generated {path} in {time.perf_counter() - start:.1f} s")
    print(f"{quads:,} quads, {os.path.getsize(path) / 1e6:.0f} MB, {os.cpu_count()} CPUs\n")
    return path


def run(command: list[str]) -> tuple[float, float, str, int]:
    """Run a child; return (wall seconds, peak RSS MiB, stdout, exit code)."""
    start = time.perf_counter()
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    out = child.stdout.read()
    _, status, usage = os.wait4(child.pid, 0)
    child.returncode = os.waitstatus_to_exitcode(status)
    return time.perf_counter() - start, usage.ru_maxrss / 1024, out, child.returncode


def measure_reader(module: str, setup: str, path: str) -> list[str]:
    if importlib.util.find_spec(module) is None:
        return ["n/a", "n/a", "n/a"]
    wall, peak, out, code = run([sys.executable, "-c", CHILD.format(setup=setup), path])
    if code != 0:
        return ["failed", f"{wall:.2f}", f"{peak:.0f}"]
    return [f"{float(out.split()[-1]):.2f}", f"{wall:.2f}", f"{peak:.0f}"]


def measure_check(path: str) -> list[str]:
    """``affinity check PATH --format json`` as a user runs it (exit 0 or 1 means it ran)."""
    executable = shutil.which("affinity")
    if executable is None or importlib.util.find_spec("affinity.cli") is None:
        return ["n/a", "n/a", "n/a"]
    wall, peak, _, code = run([executable, "check", path, "--format", "json"])
    if code not in (0, 1):
        return ["n/a", f"{wall:.2f} (exit {code})", f"{peak:.0f}"]
    return ["-", f"{wall:.2f}", f"{peak:.0f}"]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quads", type=int, default=1_000_000, help="quads in the generated OBJ (default 1,000,000)")
    parser.add_argument("--path", help="OBJ to use; generated there when missing (default: a temp file)")
    parser.add_argument("--repeat", type=int, default=1, help="runs per case; the fastest is reported")
    args = parser.parse_args(argv)

    with tempfile.TemporaryDirectory() as folder:
        path = generated_input(args.path or os.path.join(folder, f"grid_{args.quads}.obj"), args.quads, write_grid_obj)
        cases = [(name, lambda m=module, s=setup: measure_reader(m, s, path))
                 for name, (module, setup) in READERS.items()]
        cases.insert(1, ("affinity check --format json", lambda: measure_check(path)))
        print("| case | call s | process s | peak RSS MiB |")
        print("|---|---:|---:|---:|")
        for name, measure in cases:
            rows = [measure() for _ in range(args.repeat)]
            best = min(rows, key=lambda r: float(r[1].split()[0]) if r[1][0].isdigit() else float("inf"))
            print(f"| {name} | " + " | ".join(best) + " |")


if __name__ == "__main__":
    main()
