"""What the whole suite shares as fixtures: the real meshes of ../shared/meshes (``helpers.corpus``), and a
temporary result cache, a cache run an hour after the test wrote its files, a count of the files
really checked, the report of a mesh built once a session. Shared functions and constants live in ``tests/helpers/``.

Tests take the ``shared_meshes`` fixture (the folder) or a ``manifest_entry``
argument (parametrized over MANIFEST.json). Without the folder those tests skip,
and the summary says so once.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from types import SimpleNamespace

import pytest
from helpers.cli import run
from helpers.corpus import ABSENT, MANIFEST, SHARED_MESHES, manifest_entries


@pytest.fixture(scope="session")
def shared_meshes() -> Path:
    """The folder of real meshes; the test skips without it."""
    if not MANIFEST.is_file():
        pytest.skip(ABSENT)
    return SHARED_MESHES


def pytest_generate_tests(metafunc):
    """A test with a ``manifest_entry`` argument runs once per shared mesh."""
    if "manifest_entry" in metafunc.fixturenames:
        entries = manifest_entries()
        params = entries or [pytest.param(None, marks=pytest.mark.skip(reason=ABSENT))]
        metafunc.parametrize("manifest_entry", params, ids=[e["file"] for e in entries] or ["absent"])


def pytest_terminal_summary(terminalreporter):
    if not MANIFEST.is_file():
        terminalreporter.write_line(ABSENT)


@pytest.fixture(scope="session")
def report_of(tmp_path_factory):
    """``affinity report -q MESH -o PAGE`` with the default options, run once a session for each mesh (the
    modules that read a shared mesh's close-ups read the same page): ``report_of(mesh)`` -> (the run's
    result, the page's path). The page is for reading only."""
    built: dict[Path, tuple] = {}

    def report(mesh: Path) -> tuple:
        if mesh not in built:
            page = tmp_path_factory.mktemp("report") / "report.html"
            built[mesh] = run("report", "-q", str(mesh), "-o", str(page)), page
        return built[mesh]

    return report


@pytest.fixture(autouse=True, scope="session")
def result_cache_folder(tmp_path_factory):
    """The result cache lives in a temporary folder, never in the user's cache."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("AFFINITY_CACHE_DIR", str(tmp_path_factory.mktemp("result-cache")))
        yield


@pytest.fixture
def an_hour_later():
    """The result cache runs an hour after the test wrote its files, so none is in its racy window
    (which reads a file's ctime: that, unlike the mtime, cannot be dated back)."""
    from affinity.pipeline import cache as cache_module

    clock = time.time
    with pytest.MonkeyPatch.context() as patch:  # its own: a test's monkeypatch.undo() leaves it
        patch.setattr(cache_module, "time", SimpleNamespace(time=lambda: clock() + 3600))
        yield


class Counting:
    """``check_file`` that counts the files it really checks."""

    def __init__(self, check_file):
        self.paths: list[str] = []
        self.check_file = check_file

    def __call__(self, path, settings, usd=None, source=None):
        self.paths.append(os.path.basename(path))
        return self.check_file(path, settings, usd, source)


@pytest.fixture
def counting(monkeypatch) -> Counting:
    """The files checked in this process (not the cache's hits), by base name."""
    from affinity.pipeline import check as check_module

    counter = Counting(check_module.check_file)
    monkeypatch.setattr(check_module, "check_file", counter)
    return counter


@pytest.fixture(scope="module")
def big_meshes(tmp_path_factory) -> Path:
    """Sixteen copies of the grid (copies, not links: a file under two names is checked once): work for two
    workers for a few seconds (a 90,000-quad grid takes some 0.1 s to check)."""
    import shutil

    from helpers.processes import write_grid

    folder = tmp_path_factory.mktemp("big")
    write_grid(folder / "grid0.obj")
    for copy in range(1, 16):
        shutil.copyfile(folder / "grid0.obj", folder / f"grid{copy}.obj")
    return folder
