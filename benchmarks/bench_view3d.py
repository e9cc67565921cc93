"""The report's 3-D view: page size and time to first frame in headless Chromium (WebGL on SwiftShader).

Meshes: the built-in demo, MakeHuman (18,486 quads) and the shared car subdivided
three times (100,800 quads, :func:`bench_report.write_car`). Per mesh the page's
size, the 3-D view's share of it (its JSON data; three.js adds a fixed 0.74 MB),
and the time from the page's navigation to the view's first frame drawn and read
back (``affinityViews[0].firstFrame``, a fresh tab each round, median), with the
load event's time beside it. Software WebGL on 2 shared cores: a GPU is faster.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_report import SHARED, write_car
from common import ROOT, parse_with_output, write_table

sys.path.insert(0, str(ROOT / "tests"))
from helpers.chromium import CHROMIUM, WEBGL_FLAGS, DevTools, evaluate, open_page

DATA = re.compile(rb'<script type="application/json">(.*?)</script>', re.S)
TIMES = """[affinityViews.length ? affinityViews[0].firstFrame : NaN,
            performance.getEntriesByType('navigation')[0].loadEventEnd]"""


def report(paths: list[str], out: str) -> None:
    subprocess.run([sys.executable, "-m", "affinity.cli", "report", "-q", *paths, "-o", out], check=True)


def first_frames(browser: DevTools, page: Path, rounds: int) -> tuple[float, float]:
    """Median ms from navigation to the first frame and to the load event, over ``rounds`` fresh tabs."""
    frames, loads = [], []
    for _ in range(rounds):
        session = open_page(browser, page.as_uri(), 1280, 1000, timeout=120)
        frame, load = evaluate(browser, session, TIMES)
        frames.append(frame)
        loads.append(load)
        browser.call("Page.close", session=session)
    return statistics.median(frames), statistics.median(loads)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parse_with_output(parser, "the demo and a 6,300-quad car, 1 round", "folder of bench_view3d.md", argv)
    if CHROMIUM is None:
        sys.exit("bench_view3d: no chromium installed")
    levels, rounds = (1, 1) if args.small else (3, args.rounds)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        car = os.path.join(folder, "car.obj")
        source, quads = write_car(car, levels)
        meshes = [("built-in demo (3 scenes)", [])]
        if not args.small and (SHARED / "makehuman_base_hm08.obj").is_file():
            meshes.append(("makehuman_base_hm08.obj, 18,486 quads", [str(SHARED / "makehuman_base_hm08.obj")]))
        meshes.append((f"{source}, {quads:,} quads", [car]))
        browser = DevTools(Path(folder) / "profile", WEBGL_FLAGS)
        try:
            for label, paths in meshes:
                page = Path(folder) / "page.html"
                report(paths, str(page))
                raw = page.read_bytes()
                data = sum(len(match) for match in DATA.findall(raw))
                frame, load = first_frames(browser, page, rounds)
                rows.append(f"| {label} | {len(raw) / 1e6:.1f} | {data / 1e6:.1f} | {frame / 1000:.2f} | "
                            f"{load / 1000:.2f} |")
        finally:
            browser.close()
    write_table([
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.2f} after, "
        f"headless Chromium with SwiftShader WebGL, median of {rounds} fresh tab{'s' * (rounds > 1)}:",
        "",
        "| report of | page (MB) | 3-D view data (MB) | first frame (s) | load event (s) |",
        "|---|---:|---:|---:|---:|",
        *rows,
    ], args.out, "bench_view3d.md")


if __name__ == "__main__":
    main()
