"""A library checked whole and as N shards (the jobs of a CI matrix), and the shards merged back into one result.

Not a test: run it and read it.

    python benchmarks/bench_shards.py [--files 200] [--shards 4] [--sizes 512:60,2048:30,8192:10] [--runs 3]

The meshes come from bench_cluster's generator (lat-long spheres with uv: Q101 and
Q201 findings near the poles). Whole processes, each ``--no-cache --jobs 1`` (one
core of one CI runner), taking turns ``--runs`` times: the whole run, each shard
(``--shard K/N --format json``), and ``affinity merge`` of the shards' JSON into
JSON and into SARIF, every output written to a file (``-o``). Times are CPU seconds of the process (user + system: on a
machine shared with other jobs, wall time measures the others). Printed: files
and findings per shard (the balance); the best time of the whole run, of the
slowest shard (the matrix's wall time), of all shards together (its machine
time) and of each merge; the merges' peak memory (``ru_maxrss`` of the process);
and whether the merged JSON and SARIF equal the whole run's.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import tempfile

from bench_cluster import generate, parse_sizes
from bench_startup import affinity_command


def run(command: list[str]) -> tuple[float, float]:
    """CPU seconds (user + system) and peak resident MiB of one process."""
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, _, usage = os.wait4(process.pid, 0)
    process.returncode = 0  # reaped by wait4 (its status is not needed): Popen must not wait for it again
    return usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--files", type=int, default=200)
    parser.add_argument("--shards", type=int, default=4)
    parser.add_argument("--sizes", default="512:60,2048:30,8192:10", help="QUADS:PERCENT of the files")
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()

    affinity = [*affinity_command()]
    n = args.shards
    with tempfile.TemporaryDirectory() as tmp:
        library, results = os.path.join(tmp, "library"), os.path.join(tmp, "results")
        os.makedirs(results)
        size = generate(library, args.files, parse_sizes(args.sizes))
        check = [*affinity, "check", "--no-cache", "--jobs", "1", "--exit-zero", library]
        shard_files = [os.path.join(results, f"shard-{k}.json") for k in range(1, n + 1)]
        output = {f"{what} {fmt}": os.path.join(results, f"{what}.{fmt}") for what in ("whole", "merge")
                  for fmt in ("json", "sarif")}
        commands = {f"whole {fmt}": [*check, "--format", fmt, "-o", output[f"whole {fmt}"]]
                    for fmt in ("json", "sarif")}
        commands |= {f"shard {k}/{n}": [*check, "--shard", f"{k}/{n}", "--format", "json", "-o", shard_files[k - 1]]
                     for k in range(1, n + 1)}
        commands |= {f"merge {fmt}": [*affinity, "merge", "--exit-zero", "--format", fmt, "-o", output[f"merge {fmt}"],
                                      *shard_files] for fmt in ("json", "sarif")}
        best: dict[str, float] = {}
        peak: dict[str, float] = {}
        for _ in range(args.runs):
            for name, command in commands.items():
                seconds, mib = run(command)
                best[name] = min(best.get(name, seconds), seconds)
                peak[name] = max(peak.get(name, 0.0), mib)
        docs = {name: json.load(open(path)) for name, path in output.items()}
        shards = [json.load(open(path)) for path in shard_files]

    shard_times = [best[f"shard {k}/{n}"] for k in range(1, n + 1)]
    findings = docs["whole json"]["summary"]["findings"]
    print(f"{args.files} meshes ({size / 1e6:.0f} MB, sizes {args.sizes}), {findings:,} findings;"
          f" {n} shards; best of {args.runs} runs taking turns; CPU seconds, {os.cpu_count()} CPUs, "
          f"load {os.getloadavg()[0]:.1f}")
    print("files per shard:", [len(doc["files"]) for doc in shards],
          " findings per shard:", [doc["summary"]["findings"] for doc in shards])
    print(f"whole run (json): {best['whole json']:.2f} s, {peak['whole json']:.0f} MiB")
    print(f"slowest shard: {max(shard_times):.2f} s ({max(shard_times) / best['whole json']:.2f} of the whole run); "
          f"all shards: {sum(shard_times):.2f} s ({sum(shard_times) / best['whole json']:.2f})")
    for fmt in ("json", "sarif"):
        same = docs[f"merge {fmt}"] == docs[f"whole {fmt}"]
        print(f"merge to {fmt}: {best[f'merge {fmt}']:.2f} s ({best[f'merge {fmt}'] / best[f'whole {fmt}']:.2f} of "
              f"the whole run), {peak[f'merge {fmt}']:.0f} MiB; equal to the whole run's: {same}")


if __name__ == "__main__":
    main()
