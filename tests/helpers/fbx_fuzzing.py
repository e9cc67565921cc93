"""Mutated FBX files and what must hold for each (issue 59): the fuzz test's small budget and the benchmark's
large one (benchmarks/bench_bad_inputs.py --fbx) run the same harness.

Seeds: the small Blender exports of tests/data/fbx (arrays zlib-compressed, as DCC tools write them) and
uncompressed files from :mod:`helpers.fbx_binary` (every mapping of every layer, instances, materials), so
that mutations reach the arrays themselves. Mutations: the generic ones of :mod:`helpers.fuzzing` and
:func:`overwrite_word` (a 32-bit word, counts and indices included, set to a hostile value). For every file:

- ``load`` returns a mesh that passes :meth:`Mesh.validate` or raises MeshError (one line) within a time
  limit; ``lint_mesh`` runs on every mesh that loads;
- ``affinity check`` over batches (one process per batch) exits 0, 1 or 2, shows no traceback and no
  internal error, and prints one Q901 line for each unreadable file.
"""

from __future__ import annotations

import random
import struct
from collections import Counter
from pathlib import Path

import numpy as np

from .fbx_binary import MeshNode, scene_bytes
from .fuzzing import MUTATIONS, Hang, check_once, mutated_files, time_limit

DATA = Path(__file__).resolve().parents[1] / "data" / "fbx"
SEED_FILES = ("spot_control_mesh.fbx", "osd_catmark_torus.fbx", "osd_catmark_nonquads.fbx",
              "tinyobjloader_cube_vertexcol.fbx", "spot_instanced.fbx", "spot_two_uv_sets.fbx")
HOSTILE_WORDS = (0, 1, 3, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF, 0xFFFFFFFE, 1 << 24, 65536)
#: Seconds one load may take before it counts as a hang.
LOAD_SECONDS = 20
BATCH = 100


def overwrite_word(rng: random.Random, data: bytes) -> bytes:
    """One 32-bit word (at any offset past the header) set to a hostile value: a count, a length, an index."""
    if len(data) < 32:
        return data
    at = rng.randrange(27, len(data) - 4)
    return data[:at] + struct.pack("<I", rng.choice(HOSTILE_WORDS)) + data[at + 4:]


FBX_MUTATIONS = (*MUTATIONS, overwrite_word)


def synthetic_seeds() -> list[bytes]:
    """Uncompressed files: a quad and a triangle with every mapping and reference, an n-gon, two nodes
    sharing a geometry, material slots."""
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0.5], [2, 1, 0.2]], dtype=float)
    face_start, corners = np.array([0, 4, 7, 12]), np.array([0, 1, 2, 3, 1, 4, 2, 1, 4, 5, 2, 3])
    full = MeshNode("Full", points, face_start, corners,
                    uv=[("UVMap", "ByPolygonVertex", "IndexToDirect", points[:, :2], corners),
                        ("Second", "ByVertice", "Direct", points[:, 1:], None)],
                    normals=("", "ByPolygon", "Direct", np.tile([0.0, 0, 1], (3, 1)), None),
                    colors=("", "ByPolygonVertex", "IndexToDirect", np.array([[1, 0, 0, 1.0], [0, 1, 0, 1]]),
                            corners % 2),
                    materials=["a", "b"], face_slots=np.array([0, 1, 0]))
    copy = MeshNode("Copy", points, face_start, corners, geometry=0, translation=(3.0, 0.0, 0.0))
    return [scene_bytes([full]), scene_bytes([full, copy], parents=[None, 0], up_axis=2)]


def seeds() -> list[bytes]:
    return [(DATA / name).read_bytes() for name in SEED_FILES] + synthetic_seeds()


def mutated_fbx_files(folder: Path, count: int, seed: int) -> list[tuple[Path, str]]:
    """Write ``count`` mutated FBX files into ``folder``; (path, how it was made) each."""
    return mutated_files(folder, count, seed, [(".fbx", data) for data in seeds()], FBX_MUTATIONS)


def load_outcome(path: Path) -> tuple[str, str | None]:
    """``clean``, ``findings``, ``skipped`` or ``unreadable``, and a broken promise (None when the contract
    holds)."""
    from affinity.errors import MeshError, SkippedFile
    from affinity.lint import lint_mesh
    from affinity.loaders import load
    from affinity.settings import Settings

    try:
        with time_limit(LOAD_SECONDS):
            try:
                mesh = load(path)
            except SkippedFile:
                return "skipped", None
            except MeshError as error:
                if "\n" in error.reason or error.path != str(path):
                    return "unreadable", f"not one line naming the file: {error}"
                return "unreadable", None
            mesh.validate()
            hits = lint_mesh(mesh, Settings())
    except Hang:
        return "hang", f"load or lint took more than {LOAD_SECONDS} s"
    except Exception as error:
        return "crash", f"{type(error).__name__}: {error}"
    return ("findings" if any(len(h) for h in hits) else "clean"), None


def check_batch(paths: list[Path], unreadable: set[Path]) -> list[str]:
    """Run ``affinity check`` once over ``paths``; the broken promises, one line each."""
    result = check_once(paths, "--no-cache", "--quiet", timeout=600)
    if isinstance(result, str):
        return [result]
    problems = []
    if result.returncode not in (0, 1, 2) or (result.returncode == 2) != bool(unreadable):
        problems.append(f"batch starting at {paths[0]} exited {result.returncode}")
    if "Traceback" in result.stderr or "internal error" in result.stderr:
        problems.append("traceback or internal error: " + result.stderr[-2000:])
    q901 = Counter(line.split(":0: Q901 ", 1)[0] for line in result.stderr.splitlines() if ":0: Q901 " in line)
    if q901 != Counter(str(path) for path in unreadable):
        problems.append(f"Q901 lines for {sorted(q901)[:5]}..., unreadable in process: {len(unreadable)} files")
    return problems


def run_fbx_fuzz(folder: Path, count: int, seed: int) -> tuple[Counter, list[str]]:
    """Mutate, load and check ``count`` FBX files: the outcomes counted and the broken promises."""
    files = mutated_fbx_files(folder, count, seed)
    outcomes, problems, unreadable = Counter(), [], set()
    for path, how in files:
        outcome, problem = load_outcome(path)
        outcomes[outcome] += 1
        if outcome == "unreadable":
            unreadable.add(path)
        if problem:
            problems.append(f"{path.name} ({how}): {problem}")
    paths = [path for path, _ in files]
    for start in range(0, len(paths), BATCH):
        batch = paths[start:start + BATCH]
        problems += check_batch(batch, unreadable & set(batch))
    return outcomes, problems
