"""Memory of a folder run with textures stays bounded (issue 53): ``affinity check -j 1`` on N meshes, each
bound to its own 4096 x 4096 PNG, for N = 4 and 32, as peak resident sets. The decode cache keeps at most
512 MiB of texels (eight such textures); before the fix every evicted texture stayed in a reference cycle
until the cyclic collector ran, and the peak grew with N (0.67 GB at 4, 4.08 GB at 32). Goal: the peak at 32
at most 1.5x the peak at 4. Then one texture at the decode budget (8192 x 8192) in check and in render.
Not a test: run it and read it.

    python benchmarks/bench_texture_memory.py [--small] [--out DIR]

Every command is a fresh process (``python -m affinity.cli ...``, the result cache off); its peak memory is
its own largest resident set (``os.wait4``). The files are generated in a process of their own, so this one
never imports NumPy or Pillow (a child's count starts from its parent's resident set at the fork).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import parse_with_output, write_table

GOAL_RATIO = 1.5
COUNTS = (4, 32)
SIDE = 4096
BUDGET_SIDE = 8192


def write_meshes(folder: Path, count: int, side: int) -> None:
    """``count`` folders, each a 40 x 40 quad grid under a regular uv, 2% of its vertices moved so that the quads
    around them are disaffine (the visible reading decodes and samples the texture there, as on an asset with
    a few flagged quads), bound to its own ``side``^2 PNG (a smooth picture,
    different per mesh, so the PNG stays small on disk: decoded, it is ``side``^2 x 4 bytes all the same)."""
    import numpy as np
    from PIL import Image

    rng = np.random.default_rng(53)
    n = 40
    y, x = np.mgrid[0 : n + 1, 0 : n + 1].astype(float)
    corner = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel() + 1
    faces = np.column_stack([corner, corner + 1, corner + n + 2, corner + n + 1])
    ramp = np.linspace(0, 255, side, dtype=np.float32)
    for k in range(count):
        mesh = folder / f"mesh{k:02d}"
        mesh.mkdir()
        jitter = rng.uniform(-0.3, 0.3, (2, *x.shape)) * (rng.random(x.shape) < 0.02)  # a few flagged quads
        lines = ["mtllib m.mtl\nusemtl paint"]
        lines += [f"v {px:.4f} {py:.4f} 0" for px, py in zip((x + jitter[0]).ravel(), (y + jitter[1]).ravel())]
        lines += [f"vt {u:.5f} {v:.5f}" for u, v in zip(x.ravel() / n, y.ravel() / n)]
        lines += ["f " + " ".join(f"{i}/{i}" for i in face) for face in faces.tolist()]
        (mesh / "m.obj").write_text("\n".join(lines) + "\n")
        (mesh / "m.mtl").write_text("newmtl paint\nmap_Kd paint.png\n")
        red = (ramp[None, :] + 8 * k) % 256
        green = np.broadcast_to(ramp[:, None], (side, side))
        blue = (red + green[:, :1]) % 256
        picture = np.stack(np.broadcast_arrays(red, green, blue), axis=-1).astype(np.uint8)
        Image.fromarray(picture).save(mesh / "paint.png", compress_level=1)


def measured(args: list[str]) -> tuple[float, float, int]:
    """Seconds, peak MB and exit code of ``python -m affinity.cli ARGS``."""
    started = time.perf_counter()
    process = subprocess.Popen([sys.executable, "-m", "affinity.cli", *args], stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE)
    stderr = process.stderr.read().decode(errors="replace")
    _, status, usage = os.wait4(process.pid, 0)
    code = os.waitstatus_to_exitcode(status)
    seconds = time.perf_counter() - started
    print(f"  {seconds:6.2f} s {usage.ru_maxrss / 1024:6.0f} MB exit {code}: affinity {' '.join(args)}",
          file=sys.stderr, flush=True)
    if "Traceback" in stderr:
        sys.exit(f"bench_texture_memory: a traceback from affinity {' '.join(args)}:\n{stderr}")
    return seconds, usage.ru_maxrss / 1024, code


def generate(folder: Path, count: int, side: int) -> None:
    subprocess.run([sys.executable, __file__, "--write", str(folder), "--count", str(count), "--side", str(side)],
                   check=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    parser.add_argument("--write", type=Path, help=argparse.SUPPRESS)  # the generating child process
    parser.add_argument("--count", type=int, help=argparse.SUPPRESS)
    parser.add_argument("--side", type=int, help=argparse.SUPPRESS)
    args = parse_with_output(parser, "1024^2 textures and a 2048^2 budget picture: a quick run", "folder of the table",
                             argv)
    if args.write:
        write_meshes(args.write, args.count, args.side)
        return
    side, budget_side = (1024, 2048) if args.small else (SIDE, BUDGET_SIDE)
    load = os.getloadavg()[0]
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for count in COUNTS:
            folder = Path(tmp) / f"n{count}"
            folder.mkdir()
            generate(folder, count, side)
            rows[count] = measured(["check", "--isolated", "--no-cache", "-j", "1", "-q", str(folder)])
        budget = Path(tmp) / "budget"
        budget.mkdir()
        generate(budget, 1, budget_side)
        mesh = str(budget / "mesh00" / "m.obj")
        one = {"check": measured(["check", "--isolated", "--no-cache", "-q", mesh]),
               "render": measured(["render", mesh, "-o", str(budget / "out.png"), "-q"])}
    few, many = (rows[count][1] for count in COUNTS)
    lines = [f"`affinity check -j 1` on N meshes, each with its own {side}x{side} PNG (a 40x40 grid, a few "
             "quads flagged and read through the texture); fresh processes, result cache off; load average "
             f"before: {load:.2f} (a shared machine: times are indicative, peaks are not).",
             "",
             "| N | seconds | peak MB |",
             "|---:|---:|---:|",
             *(f"| {count} | {rows[count][0]:.1f} | {rows[count][1]:.0f} |" for count in COUNTS),
             "",
             f"Peak at {COUNTS[1]} / peak at {COUNTS[0]}: {many / few:.2f} (goal: at most {GOAL_RATIO:g}).",
             "",
             f"One {budget_side}x{budget_side} texture (the decode budget is 8192x8192): check peaks at "
             f"{one['check'][1]:.0f} MB, render (default size) at {one['render'][1]:.0f} MB."]
    write_table(lines, args.out, "bench_texture_memory.md" if not args.small else "bench_texture_memory_small.md")
    print(json.dumps({"ratio": many / few}), file=sys.stderr)


if __name__ == "__main__":
    main()
