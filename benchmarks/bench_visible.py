"""The visible reading's cost: ``affinity check`` on a 100k-quad mesh with and without a 2048 x 2048 texture.

Goal (issue 40): with the texture (decoded, its pyramid built, C measured on every quad Q101
flags) at most 2x the time of the same check without it, whole processes. The mesh is a
lat-long sphere of 448 x 224 quads (100,352) whose uv is its longitude and latitude, so the
rows near the poles are trapezoids that Q101 flags; the textures are generated: text (black
lines on white, the detailed case), a checker and a flat colour.

    python benchmarks/bench_visible.py [--rounds 5] [--small] [--out reports/bench]

Every case is a fresh ``affinity check --no-cache --format json`` process, the cases taking
turns; median and best wall time, and the peak memory of the best run, are reported in
``OUT/bench_visible.md``. ``--small`` makes 2 rounds on a 112 x 56 sphere.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import OUT, parse_with_output, write_table

sys.path.insert(0, str(Path(__file__).resolve().parent))
from calibration import lat_long_sphere  # noqa: E402

SIZE = 2048


def textures(folder: Path) -> dict[str, str]:
    """Case name -> texture file of the generated 2048 x 2048 textures written to ``folder``."""
    import numpy as np
    from PIL import Image, ImageDraw

    text = Image.new("RGB", (SIZE, SIZE), "white")
    draw = ImageDraw.Draw(text)
    for row in range(0, SIZE, 14):
        draw.text((4, row), "quad affinity: the split shifts the texture where uv is not affine " * 4, fill="black")
    text.save(folder / "text.png")
    cells = (np.arange(SIZE) * 64) // SIZE
    checker = np.where(((cells[:, None] + cells[None, :]) % 2)[..., None] == 0, 235, 40).astype(np.uint8)
    Image.fromarray(np.repeat(checker, 3, axis=2)).save(folder / "checker.png")
    Image.new("RGB", (SIZE, SIZE), (180, 140, 90)).save(folder / "flat.png")
    return {"text texture": "text.png", "checker texture": "checker.png", "flat texture": "flat.png"}


def run_once(path: Path) -> tuple[float, float, dict]:
    """Wall seconds, peak RSS (MiB) and the JSON summary of one ``affinity check`` process."""
    command = [sys.executable, "-m", "affinity.cli", "check", "--no-cache", "--format", "json", "--select", "Q101",
               str(path)]
    start = time.perf_counter()
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    result = subprocess.run(command, capture_output=True, text=True)
    wall = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss  # the largest child so far: see the note
    doc = json.loads(result.stdout)
    counts = doc["summary"]["by_level"]
    read = sum("shift" in f for f in doc["findings"])
    return wall, max(peak, before) / 1024, {"findings": doc["summary"]["findings"], "read": read, **counts}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    args = parse_with_output(parser, "2 rounds on a 112 x 56 sphere", "folder for bench_visible.md", argv)
    rounds, (columns, rows) = (2, (112, 56)) if args.small else (args.rounds, (448, 224))
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        sphere = lat_long_sphere(columns, rows)
        cases = {"no texture": folder / "plain.obj"}
        cases["no texture"].write_text(sphere)
        for name, texture in textures(folder).items():
            stem = Path(texture).stem
            (folder / f"{stem}.mtl").write_text(f"newmtl m\nmap_Kd {texture}\n")
            cases[name] = folder / f"{stem}.obj"
            cases[name].write_text(f"mtllib {stem}.mtl\nusemtl m\n" + sphere)
        load = os.getloadavg()
        times: dict[str, list[float]] = {name: [] for name in cases}
        peaks: dict[str, float] = {}
        summaries: dict[str, dict] = {}
        for _ in range(rounds):
            for name, path in cases.items():
                wall, peak, summary = run_once(path)
                times[name].append(wall)
                peaks[name] = peak
                summaries[name] = summary
    base = statistics.median(times["no texture"])
    lines = [
        f"Measured {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, {os.cpu_count()} CPUs, "
        f"load average {load[0]:.2f} before; a {columns} x {rows} lat-long sphere ({columns * rows:,} quads), "
        f"{SIZE} x {SIZE} textures, {rounds} rounds of fresh `affinity check --no-cache --format json --select Q101` "
        "processes taking turns.",
        "",
        "| case | Q101 findings | read through the texture | info / warning / error | median s | best s "
        "| / no texture (medians) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for name in cases:
        s = summaries[name]
        levels = " / ".join(f"{s.get(level, 0):,}" for level in ("info", "warning", "error"))
        median = statistics.median(times[name])
        lines.append(f"| {name} | {s['findings']:,} | {s['read']:,} | {levels} | {median:.2f} | "
                     f"{min(times[name]):.2f} | {median / base:.2f} |")
    lines += ["", "Goal (issue 40): every textured case at most 2x the check without the texture.",
              f"Peak memory of the largest process: {max(peaks.values()):.0f} MiB."]
    write_table(lines, args.out, "bench_visible.md")


if __name__ == "__main__":
    main()
