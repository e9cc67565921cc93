"""The NumPy rasterizer against Mesa llvmpipe through OpenGL, on the same scene, in one run.

The scene is the 200 x 100 lat-long sphere of ``bench_render.py`` (20,000 quads, uv) at
1024 x 1024. Each method is drawn by ``render.rasterize_quads`` (clip-space quads in, a
``Frame`` out) and by llvmpipe (``tests/helpers/opengl_reference.py``: split as two triangles, mvc in a
fragment shader), without culling and with back faces culled. Frames take turns, NumPy then
OpenGL, and the median of ``--frames`` frames of each is kept; the OpenGL time is clear, draw and
``glFinish`` (the data uploaded once before), the time to read the frame back into NumPy is
given beside it. The two frames must agree: faces on all but ``FACE_SHARE`` of the covered
pixels (pixel centres within rounding of an edge) and attributes to ``ATTRIBUTE_TOLERANCE``
(llvmpipe works in float32) where the faces agree; the script exits 1 otherwise. The process keeps
freed memory as the ``affinity`` command line does (``keep_freed_memory``), so that NumPy's
temporaries are not page-faulted in afresh on every frame.

    apt-get install -y libegl1 libgl1-mesa-dri libegl-mesa0 && pip install moderngl
    python benchmarks/bench_opengl.py [--frames 7] [--size 1024] [--small] [--out reports/bench]

It writes its table to ``OUT/bench_opengl.md`` (and the figures to ``bench_opengl.json``).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "benchmarks")]

from bench_render import SCENES, clip_space, hybrid_methods, uv_sphere  # noqa: E402
from common import write_table  # noqa: E402
from helpers.opengl_reference import OpenGLQuads, create_context  # noqa: E402

from affinity.commands.allocator import keep_freed_memory  # noqa: E402
from render import rasterize_quads  # noqa: E402

FACE_SHARE = 1e-4  # of the covered pixels may show another face (centres on an edge)
ATTRIBUTE_TOLERANCE = 1e-4  # uv units: float32 interpolation in llvmpipe
GOAL = 4.0  # NumPy at most 4x llvmpipe (issue 28)


def agreement(face, attrs, gl_face, gl_attrs):
    """Share of covered pixels whose face differs, and the largest attribute difference where they agree."""
    covered = (face >= 0) | (gl_face >= 0)
    same = (face == gl_face) & (face >= 0)
    differing = float(np.count_nonzero(covered & ~same)) / max(int(covered.sum()), 1)
    return differing, float(np.abs(attrs[same] - gl_attrs[same]).max(initial=0.0))


def compare(ctx, clip, uv, size, method, cull, frames):
    """One row: median times of NumPy and OpenGL frames taken in turns, and their agreement."""
    gl = OpenGLQuads(ctx, clip, uv, size, size, method, cull_backfaces=cull)
    numpy_times, gl_times, read_times = [], [], []
    try:
        for _ in range(frames):
            start = time.perf_counter()
            frame = rasterize_quads(clip, uv, size, size, method, cull_backfaces=cull)
            numpy_times.append(time.perf_counter() - start)
            start = time.perf_counter()
            gl.draw()
            gl_times.append(time.perf_counter() - start)
            start = time.perf_counter()
            gl_face, gl_attrs = gl.read()
            read_times.append(time.perf_counter() - start)
    finally:
        gl.release()
    differing, attribute_difference = agreement(frame.face, frame.attrs, gl_face, gl_attrs)
    numpy_ms, gl_ms = (1000 * statistics.median(t) for t in (numpy_times, gl_times))
    return {
        "method": method,
        "culling": cull,
        "fragments": int(frame.fragments),
        "numpy_ms": numpy_ms,
        "llvmpipe_ms": gl_ms,
        "readback_ms": 1000 * statistics.median(read_times),
        "ratio": numpy_ms / gl_ms,
        "ratio_with_readback": numpy_ms / (gl_ms + 1000 * statistics.median(read_times)),
        "faces_differing": differing,
        "attribute_difference": attribute_difference,
        "agrees": differing <= FACE_SHARE and attribute_difference <= ATTRIBUTE_TOLERANCE,
    }


def hybrid_rows(clip, uv, pole_rank, size, frames):
    """Median NumPy times of split, a per-quad array of all 'split' (the hybrid with nothing routed)
    and the hybrid with the 10% of quads nearest the poles in mvc, frames in turns."""
    cases = {
        "split": "split",
        "hybrid, nothing routed": np.full(clip.shape[0], "split"),
        "hybrid, 10% mvc": hybrid_methods(pole_rank),
    }
    times = {name: [] for name in cases}
    for _ in range(frames):
        for name, method in cases.items():
            start = time.perf_counter()
            rasterize_quads(clip, uv, size, size, method)
            times[name].append(time.perf_counter() - start)
    split = statistics.median(times["split"])
    return [
        {"case": name, "numpy_ms": 1000 * statistics.median(t), "over_split": statistics.median(t) / split}
        for name, t in times.items()
    ]


SMALL_SIZE = 128
SPHERE = {True: (200, 100), False: (40, 20)}  # full size or --small


def markdown(rows, hybrid, size, frames, quads, renderer, load):
    lines = [
        f"NumPy `rasterize_quads` against {renderer} on the {quads:,}-quad lat-long sphere at "
        f"{size}x{size}, median of {frames} frames each, taken in turns in one run "
        f"({datetime.date.today().isoformat()}; 2-CPU machine shared with other jobs, load average {load}). "
        f"llvmpipe ({os.environ.get('LP_NUM_THREADS', os.cpu_count())} threads): clear + draw + `glFinish`, "
        "data uploaded once; readback of the frame into NumPy beside it. "
        "NumPy: one thread, freed memory kept as by the `affinity` command line. "
        f"Agreement: faces on all but {FACE_SHARE:g} of the covered pixels, uv within {ATTRIBUTE_TOLERANCE:g}.",
        "",
        "| method | back faces | fragments | NumPy ms | llvmpipe ms | llvmpipe readback ms | NumPy / llvmpipe "
        "| NumPy / (llvmpipe + readback) | faces differing | max uv difference |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['method']} | {'culled' if r['culling'] else 'drawn'} | {r['fragments']:,} | {r['numpy_ms']:.1f} | "
            f"{r['llvmpipe_ms']:.1f} | {r['readback_ms']:.1f} | **{r['ratio']:.2f}** | "
            f"{r['ratio_with_readback']:.2f} | {r['faces_differing']:.1e} | {r['attribute_difference']:.1e} |"
        )
    lines += ["", "| NumPy case | ms | / split |", "|---|---:|---:|"]
    lines += [f"| {h['case']} | {h['numpy_ms']:.1f} | {h['over_split']:.2f} |" for h in hybrid]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=7, help="frames per method and renderer (median kept)")
    parser.add_argument("--size", type=int, default=1024, help="image width and height")
    parser.add_argument("--small", action="store_true", help=f"a quick case: 40 x 20 sphere, {SMALL_SIZE}^2, 3 frames")
    parser.add_argument("--out", type=Path, default=ROOT / "reports" / "bench", help="folder for the table")
    args = parser.parse_args(argv)
    size, frames = (SMALL_SIZE, min(args.frames, 3)) if args.small else (args.size, args.frames)

    keep_freed_memory()
    corners, uv, pole_rank = uv_sphere(*SPHERE[not args.small])
    clip = clip_space(corners, size, size, SCENES["sphere"][1])
    try:
        ctx = create_context()
    except Exception as error:  # moderngl missing, or no EGL device / driver
        print(f"bench_opengl: no OpenGL 4.3 context on EGL ({type(error).__name__}: {error}); install with "
              "apt-get install -y libegl1 libgl1-mesa-dri libegl-mesa0 && pip install moderngl", file=sys.stderr)
        return 2
    renderer = "Mesa {} {}".format(ctx.info["GL_VERSION"].split()[-1], ctx.info["GL_RENDERER"])
    rows = [compare(ctx, clip, uv, size, method, cull, frames) for cull in (False, True) for method in ("split", "mvc")]
    hybrid = hybrid_rows(clip, uv, pole_rank, size, frames)
    load = f"{os.getloadavg()[0]:.1f}"
    table = markdown(rows, hybrid, size, frames, clip.shape[0], renderer, load)
    write_table(table.splitlines(), args.out, "bench_opengl.md")
    (args.out / "bench_opengl.json").write_text(json.dumps({"rows": rows, "hybrid": hybrid}, indent=1) + "\n")
    disagreeing = [f"{r['method']} ({'culled' if r['culling'] else 'drawn'})" for r in rows if not r["agrees"]]
    if disagreeing:
        print("frames disagree: " + ", ".join(disagreeing), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
