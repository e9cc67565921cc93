"""Rasterizer speed (and, with --memory, peak memory) on built-in scenes.

Measures, for every scene in one run, covered fragments per second for the
``split``, ``mvc`` and ``bilinear`` methods and for a hybrid per-quad method
array that sends about 10% of the quads (those nearest the poles of the
sphere, where the split error is largest) to mvc; and the hybrid's time over
the split time. Prints a markdown table.

    python benchmarks/bench_render.py                 # all scenes at 1024x1024
    python benchmarks/bench_render.py --scene sphere --size 2048 --repeat 7
    python benchmarks/bench_render.py --memory        # 4096x4096, 1M quads: time and peak memory
    python benchmarks/bench_render.py --small --out /tmp/bench   # a quick run at 128x128

"Fragments" are covered pixel centres before the depth test (``Frame.fragments``),
counted once per method; the time is the best of ``--repeat`` runs of
``rasterize_quads`` (clip-space quads in, frame out; building the scene and
the camera transform are not timed). The process keeps freed memory as the
``affinity`` command line does (``keep_freed_memory``): NumPy's temporaries are
then not page-faulted in afresh on every frame. The table goes to
``OUT/bench_render.md`` (default ``reports/bench``).
"""

from __future__ import annotations

import argparse
import datetime
import functools
import os
import time
import tracemalloc

import numpy as np
from common import parse_with_output, write_table

from affinity.commands.allocator import keep_freed_memory
from render import frame_bounds, rasterize_quads, to_clip

METHODS = ("split", "mvc", "bilinear", "hybrid")


def uv_sphere(n_lon, n_lat):
    """Quads of a latitude-longitude sphere: corners (Q, 4, 3), uv (Q, 4, 2) and
    each quad's distance from the nearer pole in latitude bands (Q,)."""
    lon = np.linspace(0, 2 * np.pi, n_lon + 1)
    lat = np.linspace(-np.pi / 2, np.pi / 2, n_lat + 1)
    grid_lon, grid_lat = np.meshgrid(lon, lat, indexing="ij")
    points = np.stack(
        [np.cos(grid_lat) * np.cos(grid_lon), np.sin(grid_lat), -np.cos(grid_lat) * np.sin(grid_lon)], -1
    )
    uv = np.stack([grid_lon / (2 * np.pi), grid_lat / np.pi + 0.5], axis=-1)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n_lon), np.arange(n_lat), indexing="ij"))
    ring = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
    corners = np.stack([points[a, b] for a, b in ring], axis=1)
    return corners, np.stack([uv[a, b] for a, b in ring], axis=1), np.minimum(j, n_lat - 1 - j)


def wavy_grid(n):
    """A rippled n x n height field seen at a grazing angle: many small quads, varied sizes."""
    x, z = np.meshgrid(np.linspace(-4, 4, n + 1), np.linspace(-8, 2, n + 1), indexing="ij")
    y = 0.15 * np.sin(2 * x) * np.cos(1.5 * z)
    points = np.stack([x, y, z], axis=-1)
    uv = np.stack([x / 8 + 0.5, z / 10 + 0.8], axis=-1)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), indexing="ij"))
    ring = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)]
    corners = np.stack([points[a, b] for a, b in ring], axis=1)
    # No poles here: route the quads of every tenth row to mvc.
    return corners, np.stack([uv[a, b] for a, b in ring], axis=1), j % 10


SCENES = {  # name: (builder, direction the camera looks from)
    "sphere": (lambda: uv_sphere(200, 100), (0.4, 0.3, 1.0)),
    "grid": (lambda: wavy_grid(300), (0.2, 1.0, 0.6)),
    "large": (lambda: uv_sphere(16, 8), (0.4, 0.3, 1.0)),
}


def clip_space(corners, width, height, direction, fill=0.95):
    """Clip coordinates (Q, 4, 4) of the quads seen from ``direction``, their
    bounding sphere filling ``fill`` of the narrower field of view (the
    200 x 100 sphere then gives about 1.5 M fragments at 1024 x 1024)."""
    points = corners.reshape(-1, 3)
    centre = (points.min(axis=0) + points.max(axis=0)) / 2
    radius = np.linalg.norm(points - centre, axis=1).max()
    # frame_bounds fits the sphere around a box: give it the cube whose
    # sphere has radius radius / fill.
    half_side = radius / fill / np.sqrt(3)
    camera = frame_bounds(centre - half_side, centre + half_side, aspect=width / height, direction=direction)
    return to_clip(points, camera.matrix).reshape(-1, 4, 4)


def hybrid_methods(pole_rank, share=0.1):
    """'mvc' for the ``share`` of quads with the lowest rank, 'split' elsewhere."""
    methods = np.full(pole_rank.shape, "split", dtype=object)
    methods[np.argsort(pole_rank, kind="stable")[: round(share * pole_rank.size)]] = "mvc"
    return methods.astype(str)


def best_time(function, repeat):
    best, result = np.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def bench_scene(name, width, height, repeat):
    build, direction = SCENES[name]
    corners, uv, pole_rank = build()
    clip = clip_space(corners, width, height, direction)
    hybrid = hybrid_methods(pole_rank)
    rows, split_time = [], None
    for method in METHODS:
        chosen = hybrid if method == "hybrid" else method
        draw = functools.partial(rasterize_quads, clip, uv, width, height, chosen)
        seconds, frame = best_time(draw, repeat)
        split_time = seconds if method == "split" else split_time
        rows.append(
            (
                name,
                clip.shape[0],
                method,
                frame.fragments,
                int((frame.face >= 0).sum()),
                seconds,
                frame.fragments / seconds / 1e6,
                seconds / split_time,
            )
        )
    return rows


def bench_memory(size, n_lon, n_lat):
    """Time and peak traced memory of a size x size render of an n_lon x n_lat sphere (hybrid)."""
    corners, uv, pole_rank = uv_sphere(n_lon, n_lat)
    clip = clip_space(corners, size, size, SCENES["sphere"][1])
    methods = hybrid_methods(pole_rank)
    del corners
    tracemalloc.start()
    start = time.perf_counter()
    frame = rasterize_quads(clip, uv, size, size, methods)
    seconds = time.perf_counter() - start
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    inputs = clip.nbytes + uv.nbytes + methods.nbytes
    return clip.shape[0], frame.fragments, seconds, peak, inputs


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=1024, help="image width and height (default 1024)")
    parser.add_argument("--scene", choices=[*SCENES, "all"], default="all")
    parser.add_argument("--repeat", type=int, default=5, help="runs per measurement, best is kept")
    parser.add_argument("--memory", action="store_true", help="also render 4096x4096 with 1M quads")
    args = parse_with_output(parser, "a quick run: 128x128, best of 2, no --memory", "folder for bench_render.md", argv)
    if args.small:
        args.size, args.repeat, args.memory = 128, min(args.repeat, 2), False
    keep_freed_memory()

    scenes = list(SCENES) if args.scene == "all" else [args.scene]
    lines = [
        f"Rasterizer speed, {args.size}x{args.size}, best of {args.repeat} ({datetime.date.today().isoformat()}; "
        f"2-CPU machine shared with other jobs, load average {os.getloadavg()[0]:.1f}).",
        "",
        "| scene | quads | method | fragments | covered pixels | time (s) | M fragments/s | time / split |",
        "|---|---:|---|---:|---:|---:|---:|---:|",
    ]
    for name in scenes:
        for row in bench_scene(name, args.size, args.size, args.repeat):
            lines.append("| {} | {} | {} | {} | {} | {:.3f} | {:.1f} | {:.2f} |".format(*row))
    if args.memory:
        quads, fragments, seconds, peak, inputs = bench_memory(4096, 1000, 1000)
        lines += [
            "",
            "Memory, 4096x4096, sphere 1000x1000 (hybrid):",
            "",
            "| quads | fragments | time (s) | peak traced memory (GiB) | of which inputs (GiB) |",
            "|---:|---:|---:|---:|---:|",
            f"| {quads} | {fragments} | {seconds:.1f} | {peak / 2**30:.2f} | {inputs / 2**30:.2f} |",
        ]
    write_table(lines, args.out, "bench_render.md")


if __name__ == "__main__":
    main()
