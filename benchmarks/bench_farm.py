"""A library of many small files on a local Dask cluster: how much of the workers' time goes to checking.

Not a test: run it and read it.

    python benchmarks/bench_farm.py [--files 200000] [--per-file 10000] [--workers 2] [--dir DIR]

It writes ``--files`` small OBJ meshes (a 32-quad lat-long sphere with uv, about
2.5 kB each) into ``--dir`` (reused when it already holds them), starts a
``LocalCluster`` of ``--workers`` single-threaded worker processes (as
``--scheduler local:N`` does) and checks them:

- in batches (:func:`affinity.pipeline.cluster.batches`, what ``affinity check
  --scheduler`` does), every file;
- one task per file (the layout before batching), on the first ``--per-file`` files;
- in this process, one file after the other (the single-process run), every file.

For each cluster run it prints the overhead ``(wall x workers - sum of per-file check
times) / (wall x workers)``: the share of the workers' time spent on anything but
checking a file (scheduling, transfer, the client, idle tails). The per-file times are
measured on the workers, around each file's check; the wall time runs from the first
submission to the last result. The batched run's reports are compared, file by file and
as ``--format json`` writes them, with the single-process run's.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time


def generate(folder: str, files: int) -> list[str]:
    """``files`` copies of one small textured sphere in ``folder`` (kept when already there)."""
    from affinity.loaders.objwriter import write_obj
    from affinity.scenes import latlong_sphere

    os.makedirs(folder, exist_ok=True)
    template = os.path.join(folder, "template.obj.txt")  # not a mesh suffix: not checked
    if not os.path.exists(template):
        write_obj(latlong_sphere(8, 4), template)
    paths = [os.path.join(folder, f"{i // 1000:03d}", f"asset_{i:06d}.obj") for i in range(files)]
    for path in paths:
        if not os.path.exists(path):
            os.makedirs(os.path.dirname(path), exist_ok=True)
            shutil.copyfile(template, path)
    return paths


def on_cluster(client, tasks, batch_seconds: float):
    """The reports (in task order), the per-file check times on the workers and the wall time."""
    from affinity.pipeline.check import check_file
    from affinity.pipeline.cluster import check_on_cluster

    timings, reports = [], [None] * len(tasks)
    start = time.perf_counter()
    for i, report in check_on_cluster(client, tasks, check_file, timings=timings, batch_seconds=batch_seconds):
        reports[i] = report
    return reports, timings, time.perf_counter() - start


def overhead(wall: float, workers: int, timings: list[float]) -> float:
    return (wall * workers - sum(timings)) / (wall * workers)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--files", type=int, default=200_000)
    parser.add_argument("--per-file", type=int, default=10_000, help="files of the one-task-per-file run")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--dir", help="where the meshes are (or go); default: a temporary folder")
    args = parser.parse_args()

    from affinity.pipeline.check import check_file
    from affinity.pipeline.cluster import BATCH_SECONDS, batches, connect
    from affinity.settings import Settings
    from affinity.shards.journal import json_of

    with tempfile.TemporaryDirectory() as tmp:
        paths = generate(args.dir or os.path.join(tmp, "library"), args.files)
        settings = Settings()
        tasks = [(path, settings) for path in paths]
        print(f"{len(paths)} files of {os.path.getsize(paths[0])} bytes, {os.cpu_count()} CPUs, "
              f"load {open('/proc/loadavg').read().split()[0]} at the start")
        with connect(f"local:{args.workers}") as client:
            n_batches = len(batches([os.path.getsize(paths[0])] * len(paths), args.workers))
            batched, timings, wall = on_cluster(client, tasks, BATCH_SECONDS)
            print(f"batched ({n_batches} tasks):       wall {wall:8.1f} s, checking {sum(timings):8.1f} s, "
                  f"overhead {100 * overhead(wall, args.workers, timings):5.2f} %")
            few = tasks[:args.per_file]
            _, timings_one, wall_one = on_cluster(client, few, 0.0)
            print(f"one task per file ({len(few)} tasks): wall {wall_one:8.1f} s, checking {sum(timings_one):8.1f} s,"
                  f" overhead {100 * overhead(wall_one, args.workers, timings_one):5.2f} %")
        start = time.perf_counter()
        single = [check_file(path, settings) for path, settings in tasks]
        print(f"single process:                 wall {time.perf_counter() - start:8.1f} s")
        same = all(json_of(a, settings) == json_of(b, settings) for a, b in zip(batched, single))
        print(f"batched result equals the single-process run: {'yes' if same else 'NO'}; "
              f"load {open('/proc/loadavg').read().split()[0]} at the end")


if __name__ == "__main__":
    main()
