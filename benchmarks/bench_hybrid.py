"""Where the hybrid sends quads, and what it costs, on real meshes seen whole.

For every mesh of ``../shared/meshes`` (skipped when absent) and the demo sphere,
render at SIZE x SIZE with a camera framing the whole mesh, once per method
(split, hybrid, mvc), and print a markdown table: quads, share routed to mvc,
covered fragments, best-of-N time per method and hybrid / split. Routing (the
split's texture displacement per quad and its projection to pixels,
``affinity.draw.routing``) is inside the hybrid's time. ``--pixel-tolerance 1e9``
routes nothing, so hybrid / split is the cost of the routing itself.

    python benchmarks/bench_hybrid.py [--size 1024] [--repeat 3] [--pixel-tolerance PX] [MESH ...]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

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
    args = parser.parse_args()
    paths = args.meshes or (sorted(str(p) for p in SHARED.glob("*.obj")) if SHARED.exists() else [])
    scenes = ([] if args.no_demo else [("demo sphere 16x8", demo_sphere(), "z")]) + [
        (Path(p).name, load(p), up_axis(Path(p).name)) for p in paths
    ]

    print(f"| mesh ({args.size}x{args.size}) | quads | to mvc | fragments | split s | hybrid s | mvc s "
          "| hybrid / split |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, mesh, up in scenes:
        options = {method: RenderOptions(method=method, width=args.size, height=args.size, up=up, show="shaded",
                                         pixel_tolerance=args.pixel_tolerance) for method in METHODS}
        times, results = best_times(mesh, options, args.repeat)
        share = float(np.mean(results["hybrid"].methods == "mvc"))
        fragments = int(results["hybrid"].frame.fragments)
        print(f"| {name} | {mesh.counts()['quads']:,} | {share:.1%} | {fragments:,} | {times['split']:.3f} | "
              f"{times['hybrid']:.3f} | {times['mvc']:.3f} | {times['hybrid'] / times['split']:.2f} |")


if __name__ == "__main__":
    main()
