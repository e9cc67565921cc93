"""Nothing stale from the result cache (issue 47): a report is stored under the key of the bytes the
check read, and the fast path sees an in-place edit that keeps the size, inode and mtime."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from helpers.quads import SQUARE, UNIT_UV, quad_obj, trapezoid

from affinity.pipeline.cache import ResultCache
from affinity.pipeline.check import check_files
from affinity.settings import Settings

AFFINE = quad_obj([(SQUARE, UNIT_UV)])
DISAFFINE = quad_obj([(trapezoid(0.5), UNIT_UV)])


def same_size(text: str, size: int) -> str:
    """``text`` padded with a comment line to ``size`` bytes."""
    return text + "#" * (size - len(text) - 1) + "\n"


def findings(tasks, cache_dir: Path | None, jobs: int = 2) -> list[int]:
    """Findings per file of one run, with the cache in ``cache_dir`` (None: no cache)."""
    cache = None if cache_dir is None else ResultCache(str(cache_dir), tool="t")
    try:
        return [report.n_findings for report in check_files(tasks, jobs=jobs, cache=cache)]
    finally:
        if cache is not None:
            cache.close()


@pytest.mark.parametrize("an_hour", [False, True], ids=["racy", "settled"])
def test_a_file_swapped_during_a_two_job_run_then_restored_is_not_served_stale(tmp_path, monkeypatch, request,
                                                                                an_hour):
    """The parent hashes the file for its key, then the file changes before a worker reads it: the
    worker's report belongs to the new bytes and must not be stored under the old ones' key."""
    if an_hour:
        request.getfixturevalue("an_hour_later")
    mesh, other = tmp_path / "mesh.obj", tmp_path / "other.obj"
    mesh.write_text(AFFINE)
    other.write_text(DISAFFINE)
    stamp = mesh.stat()
    tasks = [(str(mesh), Settings()), (str(other), Settings())]
    expected = findings(tasks, None)
    assert expected == [0, 1]

    key = ResultCache.key

    def key_then_swap(self, path, *args, **kwargs):
        found = key(self, path, *args, **kwargs)
        if path == str(mesh):  # after the parent's hash, before the worker's read
            mesh.write_text(DISAFFINE)
        return found

    monkeypatch.setattr(ResultCache, "key", key_then_swap)
    assert findings(tasks, tmp_path / "cache") == [1, 1]  # the worker read the swapped file
    monkeypatch.undo()
    if an_hour:
        request.getfixturevalue("an_hour_later")

    mesh.write_text(AFFINE)  # `git checkout`, an undo: the old bytes, the old mtime
    os.utime(mesh, ns=(stamp.st_atime_ns, stamp.st_mtime_ns))
    assert findings(tasks, tmp_path / "cache") == expected
    assert findings(tasks, tmp_path / "cache", jobs=1) == expected


def test_an_in_place_edit_keeping_size_inode_and_mtime_is_checked_again(tmp_path, an_hour_later, counting):
    """A tool that restores mtimes: only the ctime (which no call sets back) tells the versions apart."""
    mesh = tmp_path / "mesh.obj"
    size = max(len(AFFINE), len(DISAFFINE)) + 8
    mesh.write_text(same_size(DISAFFINE, size))
    tasks = [(str(mesh), Settings())]
    assert findings(tasks, tmp_path / "cache", jobs=1) == [1]
    assert findings(tasks, tmp_path / "cache", jobs=1) == [1] and counting.paths == ["mesh.obj"]  # a hit

    before = mesh.stat()
    time.sleep(0.02)  # past a coarse file-system clock's tick, so the write moves the ctime
    with open(mesh, "r+") as fh:  # in place: same inode
        fh.write(same_size(AFFINE, size))
    os.utime(mesh, ns=(before.st_atime_ns, before.st_mtime_ns))
    after = mesh.stat()
    assert (after.st_size, after.st_ino, after.st_mtime_ns) == (before.st_size, before.st_ino, before.st_mtime_ns)
    assert findings(tasks, tmp_path / "cache", jobs=1) == [0]
    assert counting.paths == ["mesh.obj", "mesh.obj"]
