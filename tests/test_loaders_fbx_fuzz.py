"""Fuzzing the FBX loader (issue 59): mutated FBX files load as valid meshes or fail as one Q901 line, never a
traceback, a hang or a crash of the process (the harness: tests/helpers/fbx_fuzzing.py).

The suite's budget is ``AFFINITY_FBX_FUZZ_FILES`` files (default 60, a few seconds); the benchmark runs
2,000: ``python benchmarks/bench_bad_inputs.py --fbx 2000``.
"""

from __future__ import annotations

import os
import random

import pytest
from helpers.fbx_fuzzing import FBX_MUTATIONS, run_fbx_fuzz, seeds

pytest.importorskip("ufbx", reason="needs the fbx extra (ufbx)")

FUZZ_FILES = int(os.environ.get("AFFINITY_FBX_FUZZ_FILES", "60"))
FUZZ_SEED = int(os.environ.get("AFFINITY_FUZZ_SEED", "59"))


def test_mutated_fbx_files_load_or_fail_as_one_q901_line(tmp_path):
    counts, problems = run_fbx_fuzz(tmp_path, FUZZ_FILES, FUZZ_SEED)
    assert sum(counts.values()) == FUZZ_FILES
    assert not problems, f"{len(problems)} problems in {dict(counts)}:\n" + "\n".join(problems[:40])
    assert counts["unreadable"] > 0 and counts["clean"] + counts["findings"] > 0, counts  # both sides reached


def test_every_fbx_mutation_changes_every_seed():
    for data in seeds():
        for mutation in FBX_MUTATIONS:
            assert any(mutation(random.Random(k), data) != data for k in range(5)), mutation.__name__
