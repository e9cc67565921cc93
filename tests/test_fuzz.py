"""Fuzzing the loaders and ``affinity check`` with mutated meshes (issue 17).

Seeds: the small meshes of ../shared/meshes (when present), tests/data/loaders,
and generated OBJ, OFF and PLY (ASCII, binary little- and big-endian) files.
Every mutated file gets one to three mutations of every class in turn: byte
flips, truncation, inserted tokens (``nan``, ``1e999``, ``-2147483649``, ``//``,
``\\`` continuations, ...), and header counts that lie (PLY ``element`` lines,
OFF counts). For each file:

- ``load`` returns a mesh that passes :meth:`Mesh.validate` or raises the
  loader's own error (MeshError, SkippedFile), within a time limit;
- ``lint_mesh`` runs on every mesh that loads, without an exception;
- an OBJ read in 4 kB chunks gives the same mesh as read whole (or fails too);
- ``affinity check --format json`` over batches of files (one process per
  batch) exits 0, 1 or 2 with valid JSON, no traceback and no "internal error",
  and agrees with the in-process outcome: batches of clean files exit 0, of
  files with findings 1, of unreadable ones 2.

The CI budget is ``FUZZ_FILES`` files (about a minute). A long run:
``AFFINITY_FUZZ_FILES=5000 AFFINITY_FUZZ_SEED=1 python -m pytest -q tests/test_fuzz.py``.
"""

from __future__ import annotations

import json
import os
import random
import signal
import struct
import subprocess
import sys
from collections import Counter
from pathlib import Path

import numpy as np
from helpers.corpus import shared_mesh_paths
from helpers.generated_obj import FIELDS, generate_obj

from affinity.errors import MeshError, SkippedFile
from affinity.lint import lint_mesh
from affinity.loaders import load
from affinity.loaders.obj import load_obj
from affinity.settings import Settings

FUZZ_FILES = int(os.environ.get("AFFINITY_FUZZ_FILES", "600"))
FUZZ_SEED = int(os.environ.get("AFFINITY_FUZZ_SEED", "17"))
DATA = Path(__file__).parent / "data" / "loaders"
#: Seed files above this size are left out: mutations of small files find the same defects faster.
LARGEST_SEED = 300_000
#: Files per ``affinity check`` process.
BATCH = 150
#: Chunk size of the second reading of every OBJ (the mesh must not depend on it).
SMALL_CHUNK = 4096
#: Seconds one load may take before it counts as a hang.
LOAD_SECONDS = 20

TOKENS = [b"nan", b"1e999", b"-2147483649", b"//", b"\\\n", b"\\", b"-1", b"0", b"inf", b"-0", b"/",
          b"9223372036854775808", b"#", b"1/2/3/4", b"f", b"v", b"\x00", b"\xe9", b"3e8", b"4294967296"]
COUNTS = [0, 1, 2, 3, 255, 65536, 2**31 - 1, 2**31, 300_000_000, 4_000_000_000, 2**63]


def generated_off(rng: random.Random) -> bytes:
    n = rng.randrange(2, 6)
    points = [(x, y, rng.uniform(-0.1, 0.1)) for y in range(n) for x in range(n)]
    coloured = rng.random() < 0.5
    lines = ["COFF" if coloured else "OFF", f"{len(points)} {(n - 1) ** 2} 0"]
    for p in points:
        colour = [rng.randrange(256) for _ in range(3)] if coloured else []
        lines.append(" ".join(map(str, [*p, *colour])))
    for y in range(n - 1):
        for x in range(n - 1):
            a = y * n + x
            lines.append(f"4 {a} {a + 1} {a + n + 1} {a + n}")
    return ("\n".join(lines) + "\n").encode()


def generated_ply(rng: random.Random, fmt: str) -> bytes:
    n = rng.randrange(2, 6)
    vertices = [(float(x), float(y), rng.uniform(-0.1, 0.1), x / n, y / n, rng.randrange(256)) for y in range(n)
                for x in range(n)]
    faces = [[y * n + x, y * n + x + 1, (y + 1) * n + x + 1, (y + 1) * n + x] for y in range(n - 1)
             for x in range(n - 1)]
    strips = rng.random() < 0.2
    header = ["ply", f"format {fmt} 1.0", f"element vertex {len(vertices)}", "property float x", "property float y",
              "property float z", "property float s", "property float t", "property uchar red"]
    if strips:
        items = [v for face in faces for v in (face[0], face[1], face[3], face[2], -1)]
        header += ["element tristrips 1", "property list int int vertex_indices"]
        rows = [[len(items), *items]]
    else:
        header += [f"element face {len(faces)}", "property list uchar int vertex_indices"]
        rows = [[4, *face] for face in faces]
    header.append("end_header")
    head = ("\n".join(header) + "\n").encode()
    if fmt == "ascii":
        body = "".join(" ".join(map(str, v[:5])) + f" {v[5]}\n" for v in vertices)
        body += "".join(" ".join(map(str, row)) + "\n" for row in rows)
        return head + body.encode()
    order = "<" if fmt == "binary_little_endian" else ">"
    body = b"".join(struct.pack(order + "5fB", *v) for v in vertices)
    count = "i" if strips else "B"
    body += b"".join(struct.pack(order + count + f"{len(row) - 1}i", *row) for row in rows)
    return head + body


def seed_files(rng: random.Random) -> list[tuple[str, bytes]]:
    """(suffix, content) of every seed: real meshes, fixtures and generated ones."""
    seeds = []
    real = shared_mesh_paths("*.obj")
    for path in real + sorted(DATA.glob("*.*")):
        if path.suffix in (".obj", ".ply", ".off") and path.stat().st_size <= LARGEST_SEED:
            seeds.append((path.suffix, path.read_bytes()))
    for _ in range(6):
        seeds.append((".obj", generate_obj(rng).encode()))
        seeds.append((".off", generated_off(rng)))
        for fmt in ("ascii", "binary_little_endian", "binary_big_endian"):
            seeds.append((".ply", generated_ply(rng, fmt)))
    return seeds


def flip_bytes(rng: random.Random, data: bytes) -> bytes:
    data = bytearray(data)
    for _ in range(rng.choice([1, 1, 2, 5])):
        at = rng.randrange(len(data))
        data[at] = data[at] ^ (1 << rng.randrange(8)) if rng.random() < 0.5 else rng.randrange(256)
    return bytes(data)


def truncate(rng: random.Random, data: bytes) -> bytes:
    """Cut anywhere, or (half the time) after a line: the shape a copy interrupted in flight has."""
    if len(data) < 2:
        return data[:0]
    cut = rng.randrange(1, len(data))
    if rng.random() < 0.5 and data.rfind(b"\n", 0, cut) > 0:
        cut = data.rfind(b"\n", 0, cut) + 1
    return data[:cut]


def insert_token(rng: random.Random, data: bytes) -> bytes:
    """A token at a word boundary (or replacing a word), where the parser will meet it."""
    spaces = [k for k in range(len(data)) if data[k] in b" \n/"] or [0]
    at = rng.choice(spaces)
    token = rng.choice(TOKENS)
    if rng.random() < 0.5:  # replace the word after the boundary
        end = at + 1
        while end < len(data) and data[end] not in b" \n/":
            end += 1
        return data[: at + 1] + token + data[end:]
    return data[: at + 1] + token + b" " * (token != b"\\\n") + data[at + 1 :]


def lie_about_counts(rng: random.Random, data: bytes) -> bytes:
    """Change a declared count: a PLY ``element`` line, or the OFF counts line; elsewhere a number."""
    lines = data.split(b"\n")
    header = lines[: min(len(lines), 40)]
    candidates = [k for k, line in enumerate(header) if line.startswith(b"element ")]
    if data.startswith((b"OFF", b"COFF", b"NOFF", b"STOFF")) and len(lines) > 1:
        candidates = [1]
    if not candidates:
        return insert_token(rng, data)
    k = rng.choice(candidates)
    words = lines[k].split()
    if not words:
        return data
    which = len(words) - 1 if lines[k].startswith(b"element") else rng.randrange(min(2, len(words)))
    old = int(words[which]) if words[which].isdigit() else 0
    words[which] = str(rng.choice([*COUNTS, old + 1, max(old - 1, 0)])).encode()
    lines[k] = b" ".join(words)
    return b"\n".join(lines)


MUTATIONS = (flip_bytes, truncate, insert_token, lie_about_counts)


def mutated_files(folder: Path, count: int, seed: int) -> list[tuple[Path, str]]:
    """Write ``count`` mutated files into ``folder``; return (path, how it was made)."""
    rng = random.Random(seed)
    seeds = seed_files(rng)
    made = []
    for k in range(count):
        suffix, data = seeds[k % len(seeds)]
        first = MUTATIONS[k % len(MUTATIONS)]  # every class for every format, in turn
        steps = [first] + [rng.choice(MUTATIONS) for _ in range(rng.choice([0, 0, 0, 1, 2]))]
        for step in steps:
            data = step(rng, data) if data else data
        path = folder / f"fuzz_{k:05d}{suffix}"
        path.write_bytes(data)
        made.append((path, "+".join(step.__name__ for step in steps)))
    return made


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang


def load_outcome(path: Path) -> tuple[str, str | None]:
    """``clean``, ``findings``, ``skipped`` or ``unreadable``, and a problem (None when the contract holds)."""
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(LOAD_SECONDS)
    try:
        try:
            mesh = load(path)
        except MeshError as error:
            return "unreadable", (f"error names {error.path}" if error.path != str(path) else
                                  None if path.suffix != ".obj" else chunked_difference(path, None))
        mesh.validate()
        hits = lint_mesh(mesh, Settings())
        if path.suffix == ".obj" and (difference := chunked_difference(path, mesh)):
            return "crash", difference
    except SkippedFile:
        return "skipped", None
    except Hang:
        return "hang", f"load or lint took more than {LOAD_SECONDS} s"
    except Exception as error:
        return "crash", f"{type(error).__name__}: {error}"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    return ("findings" if any(len(h) for h in hits) else "clean"), None


def chunked_difference(path: Path, whole) -> str | None:
    """How the OBJ at ``path`` read in chunks of :data:`SMALL_CHUNK` bytes differs from
    ``whole``, the mesh read in one chunk (None: it was unreadable); None when it does not.

    Both must fail, or give the same mesh (which error comes first may differ: a
    chunk checks its vertices before its faces)."""
    try:
        pieces = load_obj(path, chunk_bytes=SMALL_CHUNK)
    except MeshError as error:
        return None if whole is None else f"in {SMALL_CHUNK}-byte chunks: {error.reason} (line {error.line})"
    if whole is None:
        return f"readable in {SMALL_CHUNK}-byte chunks, unreadable whole"
    for name in FIELDS:
        a, b = getattr(whole, name), getattr(pieces, name)
        if (a is None) != (b is None) or (a is not None and not np.array_equal(a, b, equal_nan=True)):
            return f"{name} differs when read in {SMALL_CHUNK}-byte chunks"
    return None


def check_batch(paths: list[Path], expected: str) -> list[str]:
    """Run ``affinity check`` once over ``paths``; the broken promises, one line each."""
    try:
        result = subprocess.run(
            [sys.executable, "-m", "affinity.cli", "check", "--isolated", "--format", "json", "-j", "1",
             *map(str, paths)], capture_output=True, text=True, timeout=300, check=False)
    except subprocess.TimeoutExpired:
        return [f"affinity check hung on a batch of {len(paths)} starting at {paths[0]}"]
    problems = []
    if result.returncode not in (0, 1, 2):
        problems.append(f"exit {result.returncode}")
    if "Traceback" in result.stderr:
        problems.append("traceback: " + result.stderr[-2000:])
    try:
        document = json.loads(result.stdout)
    except json.JSONDecodeError as error:
        return [*problems, f"invalid JSON ({error}) from a batch starting at {paths[0]}"]
    if len(document["files"]) != len(paths):
        problems.append(f"{len(document['files'])} file entries for {len(paths)} files")
    for entry in document["files"]:
        if "internal error" in str(entry.get("error", "")):
            problems.append(f"{entry['path']}: {entry['error']}")
    want = {"clean": {0}, "findings": {1}, "unreadable": {2}, "skipped": {0}}[expected]
    if result.returncode not in want:
        problems.append(f"batch of {expected} files starting at {paths[0]} exited {result.returncode}")
    return problems


def run_fuzz(folder: Path, count: int, seed: int) -> tuple[Counter, list[str]]:
    files = mutated_files(folder, count, seed)
    outcomes: dict[str, list[Path]] = {}
    problems = []
    for path, how in files:
        outcome, problem = load_outcome(path)
        outcomes.setdefault(outcome, []).append(path)
        if problem:
            problems.append(f"{path.name} ({how}): {problem}")
    for outcome in ("clean", "findings", "unreadable", "skipped"):
        paths = outcomes.get(outcome, [])
        for start in range(0, len(paths), BATCH):
            problems += check_batch(paths[start : start + BATCH], outcome)
    return Counter({k: len(v) for k, v in outcomes.items()}), problems


def test_mutated_meshes_load_consistently_or_fail_cleanly(tmp_path):
    counts, problems = run_fuzz(tmp_path, FUZZ_FILES, FUZZ_SEED)
    assert sum(counts.values()) == FUZZ_FILES >= 500 or "AFFINITY_FUZZ_FILES" in os.environ
    assert not problems, f"{len(problems)} problems in {dict(counts)}:\n" + "\n".join(problems[:40])
    # the mutations reach both sides of the contract
    assert counts["unreadable"] > 0 and counts["clean"] + counts["findings"] > 0, counts


def test_every_mutation_class_changes_every_format(tmp_path):
    rng = random.Random(5)
    for suffix, data in seed_files(rng):
        for mutation in MUTATIONS:
            changed = [mutation(random.Random(k), data) != data for k in range(5)]
            assert any(changed), (suffix, mutation.__name__)


if __name__ == "__main__":  # the long run: python tests/test_fuzz.py [FILES] [SEED]
    import tempfile
    import time

    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as scratch:
        n, s = int(sys.argv[1]) if len(sys.argv) > 1 else 5000, int(sys.argv[2]) if len(sys.argv) > 2 else 1
        tally, broken = run_fuzz(Path(scratch), n, s)
    print(f"{n} mutated files (seed {s}) in {time.perf_counter() - started:.0f} s: {dict(tally)}")
    print("\n".join(broken) or "no problems")
    sys.exit(1 if broken else 0)
