"""Where the hybrid sends quads, and what it costs, on real meshes seen whole.

For every mesh of ``../shared/meshes`` (skipped when absent) and the demo sphere,
render at SIZE x SIZE with a camera framing the whole mesh, once per method
(split, hybrid, mvc), and print a markdown table: quads, share routed to mvc,
covered fragments, best-of-N time per method and hybrid / split, and the hybrid's time over
the split's when its tolerance routes nothing (pixel tolerance 1e9). Routing (the
split's texture displacement per quad and its projection to pixels,
``affinity.draw.routing``) is inside the hybrid's time, so "nothing routed / split" is the
cost of the routing itself.

    python benchmarks/bench_hybrid.py [--size 1024] [--repeat 3] [--pixel-tolerance PX] [MESH ...]
    python benchmarks/bench_hybrid.py --small --out /tmp/bench   # the demo sphere at 128x128, best of 2

The table is written to ``OUT/bench_hybrid.md`` (default ``reports/bench``). The process keeps
freed memory as the ``affinity`` command line does.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import json
import os
import time
from pathlib import Path

import numpy as np
from common import parse_with_output, write_table

from affinity.commands.allocator import keep_freed_memory
from affinity.draw.drawing import RenderOptions, render_mesh
from affinity.loaders import load
from affinity.scenes import demo_sphere

SHARED = Path(__file__).resolve().parents[2] / "shared" / "meshes"
METHODS = ("split", "hybrid", "mvc")


def up_axis(name: str) -> str:
    """The manifest's notes say which meshes are z-up; everything else is y-up."""
    manifest = SHARED / "MANIFEST.json"
    if manifest.exists():
        for entry in json.loads(manifest.read_text()):
            if entry["file"] == name:
                return "z" if "z-up" in entry["notes"] else "y"
    return "y"


def best_times(mesh, options: dict[str, RenderOptions], repeat: int):
    """Best-of-``repeat`` seconds per method, the methods taking turns round after round so
    that whatever else the machine does weighs on all alike; and the last result of each."""
    best = dict.fromkeys(options, np.inf)
    results = {}
    for _ in range(repeat):
        for method, chosen in options.items():
            start = time.perf_counter()
            results[method] = render_mesh(mesh, chosen)
            best[method] = min(best[method], time.perf_counter() - start)
    return best, results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("meshes", nargs="*")
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--pixel-tolerance", type=float, default=0.5)
    parser.add_argument("--no-demo", action="store_true", help="leave out the demo sphere")
    args = parse_with_output(parser, "the demo sphere only, 128x128, best of 2", "folder for bench_hybrid.md")
    if args.small:
        args.size, args.repeat, args.meshes, args.no_demo = 128, 2, [], False
    keep_freed_memory()
    shared = SHARED.exists() and not args.small
    paths = args.meshes or (sorted(str(p) for p in SHARED.glob("*.obj")) if shared else [])
    scenes = ([] if args.no_demo else [("demo sphere 16x8", demo_sphere(), "z")]) + [
        (Path(p).name, load(p), up_axis(Path(p).name)) for p in paths
    ]

    lines = [
        f"`render_mesh` at {args.size}x{args.size}, each mesh framed whole, `show=\"shaded\"`, pixel tolerance "
        f"{args.pixel_tolerance:g}, best of {args.repeat}, methods in turns ({datetime.date.today().isoformat()}; "
        f"2-CPU machine shared with other jobs, load average {os.getloadavg()[0]:.1f}).",
        "",
        "| mesh | quads | to mvc | fragments | split s | hybrid s | mvc s | hybrid / split "
        "| nothing routed / split |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, mesh, up in scenes:
        options = {method: RenderOptions(method=method, width=args.size, height=args.size, up=up, show="shaded",
                                         pixel_tolerance=args.pixel_tolerance) for method in METHODS}
        # The hybrid's own cost: routing with a tolerance no displacement reaches, so every quad is split.
        options["nothing routed"] = dataclasses.replace(options["hybrid"], pixel_tolerance=1e9)
        times, results = best_times(mesh, options, args.repeat)
        share = float(np.mean(results["hybrid"].methods == "mvc"))
        fragments = int(results["hybrid"].frame.fragments)
        lines.append(f"| {name} | {mesh.counts()['quads']:,} | {share:.1%} | {fragments:,} | {times['split']:.3f} | "
                     f"{times['hybrid']:.3f} | {times['mvc']:.3f} | {times['hybrid'] / times['split']:.2f} | "
                     f"{times['nothing routed'] / times['split']:.2f} |")
    write_table(lines, args.out, "bench_hybrid.md")


if __name__ == "__main__":
    main()
