"""Text that holds no mesh costs no more than a mesh (issue 53): ``affinity check`` on 64 MB of ``o x``,
``s 1`` and ``usemtl m`` lines, and on 100,000 ``mtllib`` lines before one quad, each beside a valid textured
quad grid OBJ of the same size, as time and peak-memory ratios. Before: 74x / 8.2x for ``o x`` (40 s and
1.53 GB before "empty file"), 69x for ``s 1``, 36x for ``usemtl m``, 8.8x for the ``mtllib`` lines. Goal:
every ratio at most 3 (issue 45's bound), the file refused in one Q901 line. Not a test: run it and read it.

    python benchmarks/bench_no_geometry.py [--small] [--out DIR]

Fresh processes, result cache off; a process's peak is its own largest resident set (``os.wait4``).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_pathological import measured, valid_obj
from common import markdown_table, parse_with_output, write_table

GOAL_RATIO = 3.0


def cases(folder: Path, megabytes: float) -> list[tuple[str, Path]]:
    size = int(megabytes * 1e6)
    quad = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"
    files = {f"{megabytes:g} MB of `{line.decode().strip()}` lines": (name, line * (size // len(line)))
             for name, line in (("o.obj", b"o x\n"), ("s.obj", b"s 1\n"), ("usemtl.obj", b"usemtl m\n"))}
    files["100,000 `mtllib` lines, then a quad"] = (
        "mtllib.obj", "".join(f"mtllib lib{k}.mtl\n" for k in range(100_000)).encode() + quad)
    found = []
    for case, (name, content) in files.items():
        (folder / name).write_bytes(content)
        found.append((case, folder / name))
    return found


def write_cases(folder: Path, megabytes: float) -> list[tuple[str, str, str]]:
    """``(case, file, valid file of its size)`` for every case, written into ``folder``."""
    found = []
    for case, path in cases(folder, megabytes):
        valid = folder / f"valid-{path.name}"
        valid.write_bytes(valid_obj(path.stat().st_size))
        found.append((case, str(path), str(valid)))
    return found


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    parser.add_argument("--megabytes", type=float, default=64.0, help="size of the files (default 64)")
    parser.add_argument("--write-cases", type=Path, help=argparse.SUPPRESS)  # the generating child process
    args = parse_with_output(parser, "4 MB files: a quick run", "folder of the table", argv)
    megabytes = 4.0 if args.small else args.megabytes
    if args.write_cases:
        print(json.dumps(write_cases(args.write_cases, megabytes)))
        return
    load = os.getloadavg()[0]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        # written by a process of its own: a child's peak starts from its parent's resident set at the fork
        written = subprocess.run([sys.executable, __file__, "--write-cases", tmp, "--megabytes", str(megabytes)],
                                 check=True, capture_output=True, text=True).stdout
        for case, path, valid in json.loads(written):
            command = lambda p: ["check", "--isolated", "--no-cache", str(p)]
            seconds, peak, code, last = measured(command(path))
            valid_seconds, valid_peak, _, _ = measured(command(valid))
            rows.append([case, f"{seconds:.2f} s / {valid_seconds:.2f} s", f"{seconds / valid_seconds:.2f}",
                         f"{peak:.0f} / {valid_peak:.0f} MB", f"{peak / valid_peak:.2f}", str(code),
                         last.split("Q901 unreadable: ")[-1][:90].replace("|", "/")])
    lines = [f"`affinity check` on text with no mesh beside a valid OBJ of the same size; fresh processes; load "
             f"average before: {load:.2f} (a shared machine: times are indicative). Goal: ratios at most "
             f"{GOAL_RATIO:g}.", "",
             *markdown_table(["case", "time (case / valid)", "ratio", "peak (case / valid)", "ratio", "exit",
                              "Q901"], rows)]
    write_table(lines, args.out, "bench_no_geometry.md" if not args.small else "bench_no_geometry_small.md")


if __name__ == "__main__":
    main()
