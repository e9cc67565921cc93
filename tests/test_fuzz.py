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
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from helpers.fuzzing import MUTATIONS, Hang, check_once, mutated_files, seed_files, time_limit
from helpers.generated_obj import FIELDS

from affinity.errors import MeshError, SkippedFile
from affinity.lint import lint_mesh
from affinity.loaders import load
from affinity.loaders.obj import load_obj
from affinity.settings import Settings

pytestmark = pytest.mark.slow  # a fuzz budget of hundreds of mutated files

FUZZ_FILES = int(os.environ.get("AFFINITY_FUZZ_FILES", "600"))
FUZZ_SEED = int(os.environ.get("AFFINITY_FUZZ_SEED", "17"))
#: Files per ``affinity check`` process.
BATCH = 150
#: Chunk size of the second reading of every OBJ (the mesh must not depend on it).
SMALL_CHUNK = 4096
#: Seconds one load may take before it counts as a hang.
LOAD_SECONDS = 20


def load_outcome(path: Path) -> tuple[str, str | None]:
    """``clean``, ``findings``, ``skipped`` or ``unreadable``, and a problem (None when the contract holds)."""
    try:
        with time_limit(LOAD_SECONDS):
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
    result = check_once(paths, "--format", "json")
    if isinstance(result, str):
        return [result]
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
