"""Peak memory of ``affinity check`` on a folder of broken files (issue 17).

The folder holds files whose headers lie about their size (binary and ASCII
PLY claiming 4e9 vertices, the 177-byte binary PLY claiming 3e8, an OFF
claiming 4e9 vertices), a truncated binary PLY, a junk ``.usda``, an OBJ with
one Q101 finding and a clean OBJ. Goal: under 300 MB, every broken file one
Q901 line, exit 2. Not a test: run it and read it.

    python benchmarks/bench_bad_inputs.py [--runs 3] [--fbx 2000]

``--fbx N`` (issue 59, with the fbx extra) also writes N mutated FBX files (the
harness of tests/helpers/fbx_fuzzing.py: Blender exports and uncompressed files,
byte flips, cuts, tokens and hostile 32-bit words), loads each in this process
and checks them all with ``affinity check``: no traceback, no hang, every
unreadable file one Q901 line. It prints the outcomes and the time.

The peak is the largest resident set of the ``affinity check`` child process
(``getrusage(RUSAGE_CHILDREN).ru_maxrss``), each run in a fresh interpreter.
"""

from __future__ import annotations

import argparse
import resource
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

GOAL_MB = 300
QUAD = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"


def ply_header(fmt: str, vertices: int) -> bytes:
    return (f"ply\nformat {fmt} 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n").encode()


def write_folder(folder: Path) -> list[str]:
    """Write the broken and the good files; return the names that must be unreadable
    (the .usda too without usd-core: then its Q901 names the install command)."""
    triangle = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2)
    files = {
        "liar_binary.ply": ply_header("binary_little_endian", 4_000_000_000) + triangle,
        "liar_177_bytes.ply": ply_header("binary_little_endian", 300_000_000) + triangle,
        "liar_ascii.ply": ply_header("ascii", 4_000_000_000) + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
        "liar.off": b"OFF\n4000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
        "truncated.ply": ply_header("binary_little_endian", 3) + triangle[:30],
        "junk.usda": b"#usda 1.0\n(\n  this is not USD\n",
        "one_finding.obj": (QUAD.replace("v 1 1 0", "v 0.5 1 0") + "f 1/1 2/2 3/3 4/4\n").encode(),
        "clean.obj": (QUAD + "f 1/1 2/2 3/3 4/4\n").encode(),
    }
    for name, content in files.items():
        (folder / name).write_bytes(content)
    return sorted(name for name in files if not name.endswith(".obj"))


def one_run(folder: Path, broken: list[str]) -> tuple[float, float, int]:
    """Peak MB, seconds and exit code of one ``affinity check FOLDER``; checks its promises."""
    started = time.perf_counter()
    result = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--isolated", str(folder)],
                            capture_output=True, text=True, timeout=600, check=False)
    seconds = time.perf_counter() - started
    peak_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    q901 = sorted(Path(line.split(":")[0]).name for line in result.stderr.splitlines() if ": Q901 " in line)
    problems = [f"exit {result.returncode}, not 2"] * (result.returncode != 2)
    problems += [f"Q901 lines for {q901}, expected {broken}"] * (q901 != broken)
    problems += ["a traceback"] * ("Traceback" in result.stderr)
    problems += ["the Q101 finding is missing"] * ("one_finding.obj:9:1: Q101" not in result.stdout)
    if problems:
        sys.exit("bench_bad_inputs: " + "; ".join(problems) + "\n" + result.stderr)
    return peak_mb, seconds, result.returncode


def fuzz_fbx(count: int) -> None:
    """``count`` mutated FBX files through the fuzz harness; exits 1 on a broken promise."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from helpers.fbx_fuzzing import run_fbx_fuzz

    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as scratch:
        counts, problems = run_fbx_fuzz(Path(scratch), count, seed=2026)
    print(f"{count} mutated FBX files in {time.perf_counter() - started:.0f} s: {dict(counts)}; "
          f"{len(problems)} problems")
    if problems:
        sys.exit("\n".join(problems[:40]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--fbx", type=int, default=0, metavar="N", help="also fuzz N mutated FBX files")
    args = parser.parse_args()
    if args.fbx:
        fuzz_fbx(args.fbx)
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        broken = write_folder(folder)
        runs = [one_run(folder, broken) for _ in range(args.runs)]
    peak = max(mb for mb, _, _ in runs)  # ru_maxrss of children is the largest so far: the max over runs
    best = min(seconds for _, seconds, _ in runs)
    print(f"affinity check on {len(broken)} broken + 2 good files: exit {runs[0][2]}, "
          f"peak RSS {peak:.0f} MB (goal < {GOAL_MB} MB), best of {args.runs} {best:.2f} s")
    if peak >= GOAL_MB:
        sys.exit(1)


if __name__ == "__main__":
    main()
