"""A directory of meshes checked with ``--jobs 2`` against ``--jobs 1`` (whole processes).

The asset-pipeline case: many files, one process per core. Not a test: run it
and read it.

    python benchmarks/bench_jobs.py [--files 100] [--quads 8192] [--runs 5]

Runs alternate between the two settings; the median and the best run are reported.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile

from bench_startup import affinity_command, print_comparison, timings


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--files", type=int, default=100)
    parser.add_argument("--quads", type=int, default=8192, help="quads per mesh (a lat-long sphere)")
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()

    from affinity.loaders.objwriter import write_obj
    from affinity.scenes import latlong_sphere

    n_lon = 2 * max(2, round((args.quads / 2) ** 0.5))
    with tempfile.TemporaryDirectory() as tmp:
        first = os.path.join(tmp, "mesh_000.obj")
        write_obj(latlong_sphere(n_lon, n_lon // 2), first)
        for i in range(1, args.files):
            shutil.copyfile(first, os.path.join(tmp, f"mesh_{i:03d}.obj"))
        size_mb = os.path.getsize(first) * args.files / 1e6
        command = [*affinity_command(), "check", "--quiet"]
        timings({"warm-up": [*command, tmp]}, 1)  # the file cache
        times = timings({f"--jobs {jobs}": [*command, "--jobs", str(jobs), tmp] for jobs in (2, 1)}, args.runs)
    quads = n_lon * (n_lon // 2)
    print(f"{args.files} meshes of {quads} quads ({size_mb:.0f} MB), {args.runs} runs each, {os.cpu_count()} CPUs")
    print_comparison(times, "speed-up of --jobs 2")


if __name__ == "__main__":
    main()
