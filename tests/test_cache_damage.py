"""A damaged result cache never changes a run (issue 46): each damage gives exactly the ``--no-cache``
output and exit code with at most one warning line, and the run after it is served whole from the cache."""

from __future__ import annotations

import os
import shutil
import sqlite3
import subprocess
from pathlib import Path

import pytest
from helpers.cli import run
from helpers.quads import SQUARE, UNIT_UV, quad_obj, trapezoid

from affinity.cli import main
from affinity.pipeline.cache import DAMAGED_SUFFIX, DB_NAME

#: The single-bit flips of the sweep, spread evenly over the file.
FLIPS = 60


@pytest.fixture
def library(tmp_path: Path, an_hour_later) -> Path:
    """A textured mesh (mtllib, map_Kd), a plain one and an unreadable one, none in the racy window."""
    folder = tmp_path / "library"
    folder.mkdir()
    (folder / "tex.png").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00\x00\x40\x00\x00\x00\x40\x08\x02"
                                     b"\x00\x00\x00")
    (folder / "look.mtl").write_text("newmtl wood\nmap_Kd tex.png\n")
    (folder / "textured.obj").write_text(quad_obj([(trapezoid(), UNIT_UV), (trapezoid(0.5, 3), UNIT_UV)],
                                                  header="mtllib look.mtl\nusemtl wood"))
    (folder / "plain.obj").write_text(quad_obj([(trapezoid(0.25), UNIT_UV), (SQUARE, UNIT_UV)]))
    (folder / "broken.obj").write_text("v 0 0 0\nf 1 2 9\n")
    return folder


def check(folder: Path, capsys, *extra: str) -> tuple[int, str, list[str]]:
    """``affinity check --format json FOLDER`` in this process: exit code, stdout, stderr lines."""
    code = main(["check", "--format", "json", *extra, str(folder)])
    out, err = capsys.readouterr()
    return code, out, err.splitlines()


@pytest.fixture
def filled(library: Path, tmp_path: Path, monkeypatch, capsys) -> Path:
    """A cache filled by one run over ``library``, and its database closed (no journal left)."""
    monkeypatch.setenv("AFFINITY_CACHE_DIR", str(tmp_path / "cache"))
    check(library, capsys)
    db = tmp_path / "cache" / DB_NAME
    assert db.is_file() and not Path(f"{db}-wal").exists()
    return db


def assert_runs_as_without_cache(library: Path, capsys, counting) -> list[str]:
    """The damaged run equals ``--no-cache`` up to one warning line; the next run is a clean hit. Returns
    the warning lines."""
    code, out, err = check(library, capsys, "--no-cache")
    counting.paths.clear()
    damaged = check(library, capsys)
    warnings = [line for line in damaged[2] if line not in err]
    assert damaged[:2] == (code, out) and code == 2
    assert len(warnings) <= 1 and all(line.startswith("affinity: warning: result cache") for line in warnings)
    counting.paths.clear()
    assert check(library, capsys) == (code, out, err)
    assert counting.paths == []  # every file served from the cache
    return warnings


def damage(db: Path, sql: str) -> int:
    connection = sqlite3.connect(db)
    changed = connection.execute(sql).rowcount
    connection.commit()
    connection.close()
    return changed


def test_a_report_that_is_not_a_blob_is_a_miss(filled, library, capsys, counting):
    assert damage(filled, "UPDATE results SET report = 123") == 3  # the broken file's report is kept too
    [warning] = assert_runs_as_without_cache(library, capsys, counting)
    assert str(filled) in warning and "damaged entry" in warning


def test_dependencies_that_are_not_json_are_a_miss(filled, library, capsys, counting):
    assert damage(filled, "UPDATE files SET deps = 'xx'") >= 4  # the meshes, the library, the texture
    [warning] = assert_runs_as_without_cache(library, capsys, counting)
    assert str(filled) in warning and "damaged entry" in warning


def test_a_report_row_checksum_catches_a_valid_blob_of_another_file(filled, library, capsys, counting):
    """Two well-formed reports swapped between keys: each blob alone would load."""
    rows = sqlite3.connect(filled).execute("SELECT key, report FROM results ORDER BY key").fetchall()
    assert damage(filled, f"UPDATE results SET report = x'{rows[1][1].hex()}' WHERE key = '{rows[0][0]}'") == 1
    [warning] = assert_runs_as_without_cache(library, capsys, counting)
    assert "damaged entry" in warning


def test_tables_of_another_layout_under_this_name_are_set_aside(filled, library, capsys, counting):
    """An earlier version's rows under the same file name (the layout of schema 1) are never read."""
    filled.unlink()
    old = sqlite3.connect(filled)
    old.executescript("CREATE TABLE files (path TEXT PRIMARY KEY, size INTEGER, mtime_ns INTEGER, inode INTEGER,"
                      " digest TEXT, deps TEXT, used REAL);"
                      "CREATE TABLE results (key TEXT PRIMARY KEY, report BLOB, used REAL);"
                      "INSERT INTO results VALUES ('k', 123, 0);")
    old.close()
    [warning] = assert_runs_as_without_cache(library, capsys, counting)
    assert "set aside" in warning and Path(f"{filled}{DAMAGED_SUFFIX}").is_file()


def test_every_single_bit_flip_gives_the_fresh_result(filled, library, capsys, counting):
    """Flips spread over the file, and one bit of every stored report blob (the rows' own bytes)."""
    pristine = filled.read_bytes()
    spread = [(k * len(pristine) // FLIPS, k % 8) for k in range(FLIPS)]
    blobs = [pristine.find(b"x\x01", start) for start in _magic_offsets(pristine)]  # inside the compressed bodies
    assert len(blobs) == 3
    outcomes = set()
    for offset, bit in spread + [(offset + 3, 5) for offset in blobs]:
        flipped = bytearray(pristine)
        flipped[offset] ^= 1 << bit
        for leftover in filled.parent.iterdir():
            leftover.unlink() if leftover.is_file() else shutil.rmtree(leftover)
        filled.write_bytes(bytes(flipped))
        warnings = assert_runs_as_without_cache(library, capsys, counting)
        outcomes.add("set aside" if any("set aside" in w for w in warnings) else
                     "entry" if warnings else "unnoticed")
    assert outcomes >= {"set aside", "entry"}  # the sweep reached both kinds of damage


def _magic_offsets(data: bytes) -> list[int]:
    """Where the stored report blobs start (their magic), in file order."""
    from affinity.findings import _BLOB_MAGIC

    found, start = [], data.find(_BLOB_MAGIC)
    while start >= 0:
        found.append(start)
        start = data.find(_BLOB_MAGIC, start + 1)
    return found


def test_a_non_blob_report_as_a_user_meets_it(library, tmp_path):
    """The reproduction of the issue, in a process of its own: a traceback and no output before."""
    env_cache = tmp_path / "cache"
    first = run_cached(library, env_cache)
    damage(env_cache / DB_NAME, "UPDATE results SET report = 123")
    damaged = run_cached(library, env_cache)
    fresh = run("check", "--format", "json", "--no-cache", str(library))
    assert (damaged.returncode, damaged.stdout) == (fresh.returncode, fresh.stdout) == (first.returncode, first.stdout)
    assert "Traceback" not in damaged.stderr and damaged.stderr.count("affinity: warning: result cache") == 1


def run_cached(folder: Path, cache: Path) -> subprocess.CompletedProcess:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("AFFINITY_CACHE_DIR", str(cache))
        return run("check", "--format", "json", str(folder))


def test_files_of_other_layouts_and_set_aside_ones_go_after_a_month(filled, library, capsys):
    month = 31 * 86_400
    folder = filled.parent
    stale = [folder / "results-v1.sqlite", folder / "results-v1.sqlite-wal", folder / f"{DB_NAME}{DAMAGED_SUFFIX}"]
    kept = [folder / "results-v3-0123abcd.sqlite", folder / "notes.txt"]  # a newer version in use; not ours
    for path in stale + kept:
        path.write_bytes(b"")
    for path in stale + kept[1:]:
        os.utime(path, (path.stat().st_atime - month, path.stat().st_mtime - month))
    check(library, capsys)
    assert sorted(os.listdir(folder)) == sorted([DB_NAME, "results-v3-0123abcd.sqlite", "notes.txt"])
