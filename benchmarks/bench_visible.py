"""The visible reading's cost: ``affinity check`` on a 100k-quad mesh with and without a 2048 x 2048 texture.

Goal (issue 40): with the texture (decoded, its pyramid built, C measured on every quad Q101
flags) at most 2x the time of the same check without it, whole processes. The mesh is a
lat-long sphere of 448 x 224 quads (100,352) whose uv is its longitude and latitude, so the
rows near the poles are trapezoids that Q101 flags; the textures are generated: text (black
lines on white, the detailed case), a checker and a flat colour.

    python benchmarks/bench_visible.py [--rounds 5] [--small] [--out reports/bench]

Every case is a fresh ``affinity check --no-cache --format json`` process (every rule), the
cases taking turns; median and best wall time, median CPU time (the machine is shared: CPU
time is steadier), and the peak memory of the largest process are reported in
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

from calibration import lat_long_sphere
from common import parse_with_output, write_table

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
    """Wall seconds, CPU seconds and the JSON summary of one ``affinity check`` process."""
    command = [sys.executable, "-m", "affinity.cli", "check", "--no-cache", "--format", "json", str(path)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    doc = json.loads(result.stdout)
    q101 = [f for f in doc["findings"] if f["code"] == "Q101"]
    counts = {level: sum(f["level"] == level for f in q101) for level in ("info", "warning", "error")}
    return wall, cpu, {"findings": len(q101), "read": sum("shift" in f for f in q101), **counts}


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
        cpus: dict[str, list[float]] = {name: [] for name in cases}
        summaries: dict[str, dict] = {}
        for _ in range(rounds):
            for name, path in cases.items():
                wall, cpu, summary = run_once(path)
                times[name].append(wall)
                cpus[name].append(cpu)
                summaries[name] = summary
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024  # the largest of the processes
        after = os.getloadavg()
    base = statistics.median(times["no texture"])
    lines = [
        f"Measured {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, {os.cpu_count()} CPUs, "
        f"load average {load[0]:.2f} before, {after[0]:.2f} after (a shared machine: CPU time is the steadier "
        f"measure); a {columns} x {rows} lat-long sphere ({columns * rows:,} quads), "
        f"{SIZE} x {SIZE} textures, {rounds} rounds of fresh `affinity check --no-cache --format json` processes "
        "(every rule, as a gate runs it) taking turns.",
        "",
        "| case | Q101 findings | read through the texture | info / warning / error | median s | best s "
        "| median CPU s | / no texture (median wall) | / no texture (median CPU) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    base_cpu = statistics.median(cpus["no texture"])
    textured = [name for name in cases if name != "no texture"]
    worst_wall = max(statistics.median(times[name]) / base for name in textured)
    worst_cpu = max(statistics.median(cpus[name]) / base_cpu for name in textured)
    for name in cases:
        s = summaries[name]
        levels = " / ".join(f"{s.get(level, 0):,}" for level in ("info", "warning", "error"))
        median, cpu = statistics.median(times[name]), statistics.median(cpus[name])
        lines.append(f"| {name} | {s['findings']:,} | {s['read']:,} | {levels} | {median:.2f} | "
                     f"{min(times[name]):.2f} | {cpu:.2f} | **{median / base:.2f}** | {cpu / base_cpu:.2f} |")
    lines += ["", f"Slowest textured case / no texture (medians): {worst_wall:.2f} wall, {worst_cpu:.2f} CPU (goal of "
              "issue 40: at most 2, whole process).", f"Peak memory of the largest process: {peak:.0f} MiB."]
    write_table(lines, args.out, "bench_visible.md")


if __name__ == "__main__":
    main()
