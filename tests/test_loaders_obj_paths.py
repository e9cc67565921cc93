"""The OBJ reader's two paths agree: the fast one (lines laid out alike read as byte columns, or
tokens read as one block per kind of line) and the general one (token by token), forced with
``load_obj(..., fast=False)``. Both must give the same mesh, or the same error line, on every
fixture, on the bad inputs of the loader tests, and on the fuzzer's mutations of OBJ files;
and a bad file reads with the same error whatever the corner layout that holds it."""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import pytest
from helpers.bad_obj import BAD_FIFTH_LINE, BAD_OTHER_LINE, SQUARE
from helpers.fuzzing import MUTATIONS, seed_files
from helpers.generated_obj import FIELDS

from affinity.errors import MeshError
from affinity.loaders.obj import faces, load_obj

DATA = Path(__file__).parent / "data" / "loaders"
#: Mutated OBJ files compared (the fuzzer's own mutations of its OBJ seeds).
MUTATED = 400


def outcome(path: Path, fast: bool, chunk_bytes: int | None = None):
    """The mesh's fields (and names) as plain values, or the error as (line, reason)."""
    try:
        mesh = load_obj(path, chunk_bytes=chunk_bytes, fast=fast)
    except MeshError as error:
        return ("error", error.line, error.reason)
    fields = {name: getattr(mesh, name) for name in (*FIELDS, "colors", "notes", "group_names", "material_names")}
    return ("mesh", fields)


def assert_same_outcome(path: Path, chunk_bytes: int | None = None) -> str:
    fast, general = outcome(path, True, chunk_bytes), outcome(path, False, chunk_bytes)
    assert fast[0] == general[0], f"{path.name}: fast {fast[:3]} but general {general[:3]}"
    if fast[0] == "error":
        assert fast == general, f"{path.name}: fast {fast} but general {general}"
        return "error"
    for name, value in fast[1].items():
        other = general[1][name]
        if isinstance(value, np.ndarray) or isinstance(other, np.ndarray):
            same = (value is None) == (other is None) and (value is None or (
                value.dtype == other.dtype and np.array_equal(value, other, equal_nan=True)))
        else:
            same = value == other
        assert same, f"{path.name}: {name} differs between the fast and the general path"
    return "mesh"


BAD_TEXTS = [SQUARE + statement + "\n" for statements in BAD_FIFTH_LINE.values() for statement in statements]
BAD_TEXTS += [text for text, _, _ in BAD_OTHER_LINE]
#: Faces laid out alike, each wrong in a way the corner validator checks, after one that is
#: wrong in another: the error names the same line on both paths.
BAD_TEXTS += [
    SQUARE + "f 1 2\nf 0 2\n",  # fewer than 3 corners, then index 0: once two errors on two lines
    SQUARE + "f 1 2 3\nf 1 0 3\n",
    SQUARE + "f 1 2 3\nf 1 2 9\n",
    SQUARE + "f 1 2 -9\nf 1 2 3\n",  # relative index before the first vertex
    SQUARE + "vt 0 0\nf 1/1 2/1 3/1\nf 1/1 2/1 3\n",
    SQUARE + "vt 0 0\nf 1/1 2/1 3/1\nf 1/1 2/1 3/0\n",
    SQUARE + "vt 0 0\nf 1/1 2/x 3/1\nf 1/1 2/0 3/1\n",
    SQUARE + "f 1// 2// 3//\nf 1/// 2// 3//\n",
    SQUARE + "f 1 2 3 4\nf 1 2 3\nf 1 2 0\n",
    SQUARE + "vn 0 0 1\nf 1//-1 2//-1 3//-1\nf 1//-2 2//1 3//1\n",
]


@pytest.mark.parametrize("text", BAD_TEXTS)
def test_bad_inputs_fail_alike_on_both_paths(tmp_path, text):
    path = tmp_path / "bad.obj"
    path.write_text(text)
    assert assert_same_outcome(path) == "error"


@pytest.mark.parametrize("path", sorted(DATA.glob("*.obj")), ids=lambda p: p.name)
def test_fixtures_read_alike_on_both_paths(path):
    assert assert_same_outcome(path) == "mesh"
    assert assert_same_outcome(path, chunk_bytes=61) == "mesh"


@pytest.mark.slow  # a fuzz budget
def test_fuzzed_files_read_or_fail_alike_on_both_paths(tmp_path):
    rng = random.Random(39)
    obj_seeds = [(suffix, data) for suffix, data in seed_files(rng) if suffix == ".obj"]
    outcomes = []
    for k in range(MUTATED):
        data = obj_seeds[k % len(obj_seeds)][1]
        for step in [MUTATIONS[k % len(MUTATIONS)], rng.choice(MUTATIONS)][: 1 + k % 2]:
            data = step(rng, data) if data else data
        path = tmp_path / f"fuzz_{k:04d}.obj"
        path.write_bytes(data)
        outcomes.append(assert_same_outcome(path, chunk_bytes=None if k % 3 else 4096))
    assert 0 < outcomes.count("error") < len(outcomes), "the mutations reach both outcomes"


#: Face lines wrong in each of the validator's checks: (the wrong face line, words of the error).
FACE_ERRORS = [("f 1 0 2", "bad index '0'"), ("f 1 2 x", "bad index 'x'"), ("f 1/1/1/1 2 3", "malformed"),
               ("f 1 2", "face with 2 corners"), ("f 1/1 2/1 3", "mix the forms")]


@pytest.mark.parametrize("fast", [True, False], ids=["fast", "general"])
@pytest.mark.parametrize("face, words", FACE_ERRORS)
def test_both_paths_raise_face_errors_through_the_one_validator(tmp_path, monkeypatch, fast, face, words):
    """Whichever path reads the faces, the error is the one :func:`checked_corners` raised."""
    raised = []
    real = faces.checked_corners

    def spied(*args):
        try:
            return real(*args)
        except MeshError as error:
            raised.append((error.line, error.reason))
            raise

    monkeypatch.setattr(faces, "checked_corners", spied)
    path = tmp_path / "bad_face.obj"
    path.write_text(SQUARE + "vt 0 0\n" + "f 1 2 3\n" * 3 + face + "\n" + "f 2 3 4\n" * 3)
    with pytest.raises(MeshError) as caught:
        load_obj(path, fast=fast)
    assert words in caught.value.reason and caught.value.line == 9
    assert raised[-1] == (9, caught.value.reason)
