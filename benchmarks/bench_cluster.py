"""An asset library checked with ``--jobs 2``, on a Dask cluster, and again from the result cache.

Not a test: run it and read it.

    python benchmarks/bench_cluster.py [--dir DIR] [--files 2000] [--sizes 512:60,2048:27,8192:10,32768:3] [--remote]
    python benchmarks/bench_cluster.py --generate-only --dir DIR      # just write the meshes

The generator writes ``--files`` OBJ meshes (lat-long spheres with uv: Q101 and
Q201 findings near the poles) in a mix of sizes, ``QUADS:PERCENT`` each, into
``--dir`` (reused when it already holds them; a temporary folder otherwise).
Then, as whole ``affinity check --quiet`` processes, one run each:

- ``--jobs 2`` and ``--scheduler local:2`` without the cache, on every file and
  on one file: the difference of the differences is the cluster's cost per
  file, start-up (interpreter, LocalCluster) excluded;
- with ``--remote``, the same against a ``dask scheduler`` and ``dask worker
  --nworkers 2`` started as separate processes, as on a multi-machine cluster;
- ``--jobs 2`` with an empty cache (the first run of a user: it fills the
  cache), then again, ``--repeat`` times (every file answered by the cache;
  the median is reported), and once with ``--scheduler`` set to an address
  nothing listens on (nothing to submit, so the cluster is never reached).

Every run's output is compared with the first one's.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from bench_startup import affinity_command


def parse_sizes(text: str) -> dict[int, float]:
    """``"512:70,2048:30"`` -> {512: 0.7, 2048: 0.3} (quads per mesh -> share of the files)."""
    sizes = {int(q): float(p) for q, p in (item.split(":") for item in text.split(","))}
    total = sum(sizes.values())
    return {quads: share / total for quads, share in sizes.items()}


def generate(folder: str, files: int, sizes: dict[int, float]) -> int:
    """Write ``files`` meshes into ``folder`` (kept when already there); returns their total bytes."""
    from affinity.loaders.objwriter import write_obj
    from affinity.scenes import latlong_sphere

    os.makedirs(folder, exist_ok=True)
    templates = {}
    for quads in sizes:
        n_lat = max(2, round((quads / 2) ** 0.5))
        templates[quads] = os.path.join(folder, f"template_{quads}.obj.txt")  # not a mesh suffix: not checked
        if not os.path.exists(templates[quads]):
            write_obj(latlong_sphere(2 * n_lat, n_lat), templates[quads])
    counts = {quads: round(share * files) for quads, share in sizes.items()}
    counts[max(sizes, key=sizes.get)] += files - sum(counts.values())
    names = [(quads, k) for quads, count in counts.items() for k in range(count)]
    total = 0
    for i, (quads, _) in enumerate(names):
        target = os.path.join(folder, f"asset_{i:05d}_{quads}q.obj")
        if not os.path.exists(target):
            shutil.copyfile(templates[quads], target)
        total += os.path.getsize(target)
    return total


def timed(command: list[str], env: dict[str, str]) -> tuple[float, str, int]:
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True, env=env)
    return time.perf_counter() - start, result.stdout, result.returncode


class Remote:
    """``dask scheduler`` and ``dask worker --nworkers 2 --nthreads 1`` as separate processes on 127.0.0.1."""

    def __init__(self, tmp: str):
        dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
        scheduler_file = os.path.join(tmp, "scheduler.json")
        log = subprocess.DEVNULL
        self.processes = [subprocess.Popen([*dask, "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                            "--scheduler-file", scheduler_file], stdout=log, stderr=log)]
        while not os.path.exists(scheduler_file):
            time.sleep(0.2)
        time.sleep(0.5)  # the file is written before it is complete
        import json

        with open(scheduler_file) as f:
            self.address = json.load(f)["address"]
        self.processes.append(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", self.address, "--nworkers", "2", "--nthreads", "1",
             "--no-dashboard", "--host", "127.0.0.1"], stdout=log, stderr=log))
        from distributed import Client

        with Client(self.address, timeout=60) as client:
            client.wait_for_workers(2, timeout=120)

    def stop(self) -> None:
        for process in reversed(self.processes):
            process.terminate()
            process.wait(timeout=30)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dir", help="where the meshes are (or go); default: a temporary folder")
    parser.add_argument("--files", type=int, default=2000)
    parser.add_argument("--sizes", default="512:60,2048:27,8192:10,32768:3",
                        help="QUADS:PERCENT,... (default: about 1.1 GB for 2,000 files)")
    parser.add_argument("--repeat", type=int, default=5, help="cached runs; their median is reported")
    parser.add_argument("--remote", action="store_true", help="also run against a dask scheduler/worker pair")
    parser.add_argument("--generate-only", action="store_true")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        folder = args.dir or os.path.join(tmp, "assets")
        size = generate(folder, args.files, parse_sizes(args.sizes))
        print(f"{args.files} meshes ({args.sizes} quads:percent), {size / 1e6:.0f} MB in {folder}, "
              f"{os.cpu_count()} CPUs")
        if args.generate_only:
            return
        one = os.path.join(tmp, "one")
        os.makedirs(one)
        meshes = [os.path.join(folder, n) for n in os.listdir(folder) if n.endswith(".obj")]
        shutil.copyfile(min(meshes, key=os.path.getsize), os.path.join(one, "asset.obj"))
        env = {**os.environ, "AFFINITY_CACHE_DIR": os.path.join(tmp, "cache")}
        check = [*affinity_command(), "check", "--quiet"]
        for name in os.listdir(folder):  # warm the file cache: every run reads from memory
            with open(os.path.join(folder, name), "rb") as f:
                while f.read(1 << 24):
                    pass

        remote = Remote(tmp) if args.remote else None
        runners = {"--jobs 2": ["--jobs", "2"], "--scheduler local:2": ["--scheduler", "local:2"]}
        if remote is not None:
            runners["--scheduler tcp:// (2 workers)"] = ["--scheduler", remote.address]
        try:
            results, reference = {}, None
            for name, flags in runners.items():
                whole, out, code = timed([*check, "--no-cache", *flags, folder], env)
                single, _, _ = timed([*check, "--no-cache", *flags, one], env)
                reference = reference or (out, code)
                results[name] = (whole, single, (out, code) == reference)
        finally:
            if remote is not None:
                remote.stop()
        filling, out_fill, code_fill = timed([*check, "--jobs", "2", folder], env)
        again = [timed([*check, "--jobs", "2", folder], env) for _ in range(args.repeat)]
        cached = statistics.median(seconds for seconds, _, _ in again)
        same_cached = all((out, code) == reference for _, out, code in again)
        unreached, out_unreached, code_unreached = timed([*check, "--scheduler", "tcp://127.0.0.1:9", folder], env)

    base_whole, base_single, _ = results["--jobs 2"]
    print(f"{'run':<34} {'all files':>10} {'one file':>9} {'per file':>9} {'over --jobs 2':>14}  same output")
    for name, (whole, single, same) in results.items():
        per_file = (whole - single) / (args.files - 1)
        overhead = ((whole - single) - (base_whole - base_single)) / (args.files - 1)
        print(f"{name:<34} {whole:9.1f}s {single:8.2f}s {per_file * 1000:7.2f}ms {overhead * 1000:+12.2f}ms  "
              f"{'yes' if same else 'NO'}")
    print(f"{'--jobs 2, empty cache (fills it)':<34} {filling:9.1f}s"
          f"{'':>29}  {'yes' if (out_fill, code_fill) == reference else 'NO'}")
    print(f"{'--jobs 2, every file cached':<34} {cached:9.2f}s"
          f"{'':>29}  {'yes' if same_cached else 'NO'}   (median of {args.repeat}: "
          f"{', '.join(f'{seconds:.2f}' for seconds, _, _ in again)} s)")
    print(f"{'--scheduler (dead), every file cached':<34} {unreached:9.2f}s"
          f"{'':>29}  {'yes' if (out_unreached, code_unreached) == reference else 'NO'}")
    print(f"cached run: {filling / cached:.1f}x faster than the first run (which filled the cache), "
          f"{base_whole / cached:.1f}x faster than --jobs 2 without the cache; "
          f"{(cached - base_single) / args.files * 1000:.2f} ms per cached file")


if __name__ == "__main__":
    main()
