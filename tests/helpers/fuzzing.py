"""The fuzzer's seeds and mutations (tests/test_fuzz.py), shared with the tests that read mutated files."""

from __future__ import annotations

import random
import signal
import struct
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

from helpers.corpus import shared_mesh_paths
from helpers.generated_obj import generate_obj

DATA = Path(__file__).resolve().parents[1] / "data" / "loaders"
#: Seed files above this size are left out: mutations of small files find the same defects faster.
LARGEST_SEED = 300_000

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


def mutated_files(folder: Path, count: int, seed: int, seeds: list[tuple[str, bytes]] | None = None,
                  mutations: tuple = MUTATIONS) -> list[tuple[Path, str]]:
    """Write ``count`` mutated files into ``folder``; return (path, how it was made). ``seeds``: (suffix,
    content) pairs (default :func:`seed_files`), each mutated by one to three of ``mutations``."""
    rng = random.Random(seed)
    seeds = seed_files(rng) if seeds is None else seeds
    made = []
    for k in range(count):
        suffix, data = seeds[k % len(seeds)]
        first = mutations[k % len(mutations)]  # every class for every format, in turn
        steps = [first] + [rng.choice(mutations) for _ in range(rng.choice([0, 0, 0, 1, 2]))]
        for step in steps:
            data = step(rng, data) if data else data
        path = folder / f"fuzz_{k:05d}{suffix}"
        path.write_bytes(data)
        made.append((path, "+".join(step.__name__ for step in steps)))
    return made


class Hang(Exception):
    """A load or lint that took longer than its :func:`time_limit`."""


@contextmanager
def time_limit(seconds: int):
    """Raise :class:`Hang` in the block once ``seconds`` have passed (SIGALRM)."""

    def alarm(signum, frame):
        raise Hang

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def check_once(paths: list[Path], *options: str, timeout: int = 300) -> subprocess.CompletedProcess | str:
    """``affinity check --isolated -j 1 OPTIONS PATHS`` in one process; its result, or the line saying it hung."""
    try:
        return subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--isolated", "-j", "1", *options,
                               *map(str, paths)], capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return f"affinity check hung on a batch of {len(paths)} starting at {paths[0]}"
