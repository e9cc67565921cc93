"""Bad input costs no more than good input (issue 45): check, render and report on pathological
files generated on the fly, each beside a valid file of the same size, as time and peak-memory ratios.

Cases: zero-filled, random bytes, text with no line break (OBJ-looking words), a face of 100,000
corners, 10 million one-triangle faces (80 MB), a face whose every index is the same, deeply nested
USD references and a USD stage of 100,000 empty prims. The valid file of each is a textured quad
grid (OBJ; for USD a stage holding such a mesh) of the same number of bytes. Goal: every ratio at
most 3, or a clear Q901 line (exit 2) well before that. Then two scaling lines (issue 47): ``mtllib``
statements, 10,000 against 100,000 (linear: a time ratio near 10), and ``render.rasterize_quads`` on
10 million triangles in one process with its peak memory (goal: under 4 GB). Not a test: run it and
read it.

    python benchmarks/bench_pathological.py [--small] [--out DIR]

Every command is a fresh process (``python -m affinity.cli ...``, the result cache off); its peak
memory is its own largest resident set (``os.wait4``). A child's count starts from its parent's
resident set at the fork, so the files are generated in a process of their own and this one
never imports NumPy.
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

GOAL_RATIO = 3.0
GOAL_RENDER_GB = 4.0
SIZE = "320x240"


def valid_obj(size: int) -> bytes:
    """A textured quad grid of exactly ``size`` bytes (a comment pads the last few)."""
    import numpy as np

    n = max(2, int((size / 90) ** 0.5))  # about 90 bytes a grid point: v, vt and a quarter of the faces
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), indexing="ij"))
    lines = [f"v {x:.6f} {y:.6f} {0.1 * np.sin(x + y):.6f}\n" for x, y in zip(i / n, j / n)]
    lines += [f"vt {x:.6f} {y:.6f}\n" for x, y in zip(i / n, j / n)]
    parts, length = ["".join(lines)], sum(map(len, lines))
    for k in (a * n + b + 1 for a in range(n - 1) for b in range(n - 1)):
        face = f"f {k}/{k} {k + n}/{k + n} {k + n + 1}/{k + n + 1} {k + 1}/{k + 1}\n"
        if length + len(face) > size - 2:
            break
        parts.append(face)
        length += len(face)
    body = "".join(parts).encode()
    return body + b"#" * (size - len(body) - 1) + b"\n"


def valid_usda(size: int) -> bytes:
    """A .usda stage holding one quad-grid mesh, of exactly ``size`` bytes."""
    head = b'#usda 1.0\ndef Mesh "grid" {\n    point3f[] points = ['
    n = max(2, int((size / 60) ** 0.5))
    points = ", ".join(f"({x / n:.5f}, {y / n:.5f}, 0)" for x in range(n) for y in range(n))
    quads = [(a * n + b, (a + 1) * n + b, (a + 1) * n + b + 1, a * n + b + 1)
             for a in range(n - 1) for b in range(n - 1)]
    counts, indices = [], []
    budget = size - len(head) - len(points) - 120
    for quad in quads:
        budget -= len(", ".join(map(str, quad))) + 5
        if budget < 0:
            break
        counts.append("4")
        indices.append(", ".join(map(str, quad)))
    text = (head.decode() + points + "]\n    int[] faceVertexCounts = [" + ", ".join(counts)
            + "]\n    int[] faceVertexIndices = [" + ", ".join(indices) + "]\n}\n").encode()
    return text + b"#" * (size - len(text) - 1) + b"\n" if len(text) < size else text


def write_cases(folder: Path, megabytes: float, scale: int) -> list[tuple[str, Path, Path]]:
    """``(case, pathological file, valid file of the same size)`` for every case, written into ``folder``."""
    import numpy as np

    size = int(megabytes * 1e6)
    rng = np.random.default_rng(45)
    quad = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    corners = 100_000 // scale
    fan = "".join(f"v {np.cos(t):.6f} {np.sin(t):.6f} 0\n" for t in np.linspace(0, 2 * np.pi, corners, endpoint=False))
    files = {
        "zero-filled": ("zeros.obj", b"\0" * size),
        "random bytes": ("random.obj", rng.integers(0, 256, size, dtype=np.uint8).tobytes()),
        "text with no line break": ("line.obj", (b"v 0.5 0.5 0.5 " * (size // 14 + 1))[:size]),
        f"a face of {corners:,} corners": ("fan.obj", (fan + "f " + " ".join(map(str, range(1, corners + 1))) + "\n")
                                           .encode()),
        f"{10_000_000 // scale:,} one-triangle faces": ("triangles.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                                        + b"f 1 2 3\n" * (10_000_000 // scale)),
        "a face with every index the same": ("same.obj", quad + b"f " + b"1 " * (size // 2 - 40) + b"\n"),
    }
    cases = []
    for case, (name, content) in files.items():
        (folder / name).write_bytes(content)
        (folder / f"valid-{name}").write_bytes(valid_obj(len(content)))
        cases.append((case, folder / name, folder / f"valid-{name}"))
    depth = 1000 // scale
    nested = folder / "nested"
    nested.mkdir()
    (nested / f"level{depth}.usda").write_bytes(valid_usda(600))
    for level in range(depth):
        reference = f"@./level{level + 1}.usda@</grid>"
        (nested / f"level{level}.usda").write_text(
            f'#usda 1.0\n(\n    defaultPrim = "grid"\n)\ndef "grid" (\n    references = {reference}\n)\n{{\n}}\n')
    total = sum(p.stat().st_size for p in nested.iterdir())
    (folder / "valid-nested.usda").write_bytes(valid_usda(total))
    cases.append((f"USD references {depth:,} deep", nested / "level0.usda", folder / "valid-nested.usda"))
    prims = 100_000 // scale
    empty = "#usda 1.0\n" + "".join(f'def Xform "p{k}" {{\n}}\n' for k in range(prims))
    (folder / "empty.usda").write_text(empty)
    (folder / "valid-empty.usda").write_bytes(valid_usda(len(empty)))
    cases.append((f"USD stage of {prims:,} empty prims", folder / "empty.usda", folder / "valid-empty.usda"))
    return cases


def measured(args: list[str]) -> tuple[float, float, int, str]:
    """Seconds, peak MB, exit code and last stderr line of ``python -m affinity.cli ARGS``."""
    started = time.perf_counter()
    process = subprocess.Popen([sys.executable, "-m", "affinity.cli", *args], stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE)
    stderr = process.stderr.read().decode(errors="replace")
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    seconds = time.perf_counter() - started
    print(f"  {seconds:6.2f} s {usage.ru_maxrss / 1024:6.0f} MB exit {process.returncode}: affinity {' '.join(args)}",
          file=sys.stderr, flush=True)
    if "Traceback" in stderr:
        sys.exit(f"bench_pathological: a traceback from affinity {' '.join(args)}:\n{stderr}")
    last = next((line for line in reversed(stderr.splitlines()) if "Q901" in line or "error" in line), "")
    return seconds, usage.ru_maxrss / 1024, process.returncode, last


def commands(path: str, out: Path) -> dict[str, list[str]]:
    return {
        "check": ["check", "--isolated", "--no-cache", str(path)],
        "render": ["render", str(path), "-o", str(out / "out.png"), "--size", SIZE, "-q"],
        "report": ["report", str(path), "-o", str(out / "out.html"), "--size", SIZE, "--max-views", "2", "-q"],
    }


def scaling_lines(folder: Path, scale: int) -> list[str]:
    """The mtllib time ratio (10,000 against 100,000 lines) and the 10-million-triangle render's peak."""
    quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"
    seconds = {}
    for count in (10_000 // scale, 100_000 // scale):
        path = folder / f"mtllib{count}.obj"
        path.write_text("".join(f"mtllib lib{k}.mtl\n" for k in range(count)) + quad)
        seconds[count] = min(measured(["check", "--isolated", "--no-cache", str(path)])[0] for _ in range(2))
    few, many = sorted(seconds)
    triangles = 10_000_000 // scale
    code = ("import numpy as np, resource, time; from render import rasterize_quads\n"
            f"n = {triangles}; k = int((n / 2) ** 0.5)\n"
            "x, y = np.meshgrid(np.linspace(-0.9, 0.9, k + 1), np.linspace(-0.9, 0.9, k + 1), indexing='ij')\n"
            "p = np.stack([x, y, 0.5 * x * y, np.ones_like(x)], -1)\n"
            "q = np.stack([p[:-1, :-1], p[1:, :-1], p[1:, 1:], p[1:, 1:]], 2).reshape(-1, 4, 4)\n"
            "r = np.stack([p[:-1, :-1], p[1:, 1:], p[:-1, 1:], p[:-1, 1:]], 2).reshape(-1, 4, 4)\n"
            "clip = np.concatenate([q, r]); del p, q, r, x, y\n"
            "uv = clip[..., :2].copy(); t = time.perf_counter()\n"
            "frame = rasterize_quads(clip, uv, 1920, 1080)\n"
            "print(len(clip), time.perf_counter() - t, (frame.face >= 0).sum(), frame.fragments)\n")
    started = time.perf_counter()
    process = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE)
    printed = process.stdout.read().decode().split()
    _, _, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - started
    drawn, draw_seconds = int(printed[0]), float(printed[1])
    peak_gb = usage.ru_maxrss / 1024**2
    return [
        "",
        "| scaling | measured | goal |",
        "|---|---|---|",
        f"| `mtllib` lines, {few:,} against {many:,} (check, fresh process, best of 2) | "
        f"{seconds[few]:.2f} s against {seconds[many]:.2f} s: {seconds[many] / seconds[few]:.1f}x "
        f"for {many // few}x the lines | linear (was quadratic: 16,000 lines 8 s) |",
        f"| `render.rasterize_quads` on {drawn:,} triangles (a 1920x1080 grid, uv) | "
        f"{draw_seconds:.1f} s drawing ({wall:.1f} s with set-up), peak {peak_gb:.2f} GB "
        f"| under {GOAL_RENDER_GB:g} GB |",
    ]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    parser.add_argument("--megabytes", type=float, default=10.0, help="size of the byte-sized cases (default 10)")
    parser.add_argument("--write-cases", type=Path, help=argparse.SUPPRESS)  # the generating child process
    args = parse_with_output(parser, "1 MB cases, a tenth of the counts: a quick run", "folder of the table", argv)
    scale = 10 if args.small else 1
    megabytes = 1.0 if args.small else args.megabytes
    if args.write_cases:
        print(json.dumps([(case, str(bad), str(valid)) for case, bad, valid in
                          write_cases(args.write_cases, megabytes, scale)]))
        return
    load = os.getloadavg()[0]
    lines = [f"Pathological inputs beside valid files of the same size ({megabytes:g} MB for the byte-sized "
             f"cases), check / render / report, each a fresh process; load average before: {load:.2f}.",
             "",
             "| case | command | bad: s, MB, exit | valid: s, MB | time ratio | memory ratio | outcome |",
             "|---|---|---|---|---|---|---|"]
    worst = 0.0
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        written = subprocess.run([sys.executable, __file__, "--write-cases", scratch, "--megabytes", str(megabytes),
                                  *(["--small"] if args.small else [])], capture_output=True, text=True, check=True)
        for case, bad, valid in json.loads(written.stdout):
            for command, bad_args in commands(bad, folder).items():
                seconds, mb, code, last = measured(bad_args)
                valid_seconds, valid_mb, _, _ = measured(commands(valid, folder)[command])
                ratios = seconds / valid_seconds, mb / valid_mb
                outcome = last.replace(scratch + os.sep, "").split(": ", 1)[-1][:90] if code else "read"
                if code == 0:
                    worst = max(worst, *ratios)
                lines.append(f"| {case} | {command} | {seconds:.2f}, {mb:.0f}, {code} | {valid_seconds:.2f}, "
                             f"{valid_mb:.0f} | {ratios[0]:.2f} | {ratios[1]:.2f} | {outcome} |")
        lines += scaling_lines(folder, scale)
    write_table(lines, args.out, "bench_pathological.md")
    print(f"worst ratio of a file that was read: {worst:.2f} (goal at most {GOAL_RATIO:g})", file=sys.stderr)


if __name__ == "__main__":
    main()
