"""What the whole suite shares: the real meshes of ../shared/meshes, and a temporary result cache.

Tests take the ``shared_meshes`` fixture (the folder) or a ``manifest_entry``
argument (parametrized over MANIFEST.json). Without the folder those tests skip,
and the summary says so once.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

SHARED_MESHES = Path(__file__).resolve().parents[2] / "shared" / "meshes"
MANIFEST = SHARED_MESHES / "MANIFEST.json"
ABSENT = f"{SHARED_MESHES} is absent: the tests on real meshes were skipped"


def manifest_entries() -> list[dict]:
    """MANIFEST.json's entries (file, counts, licence, ...); empty without the folder."""
    return json.loads(MANIFEST.read_text(encoding="utf-8")) if MANIFEST.is_file() else []


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


@pytest.fixture(autouse=True, scope="session")
def result_cache_folder(tmp_path_factory):
    """The result cache lives in a temporary folder, never in the user's cache."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("AFFINITY_CACHE_DIR", str(tmp_path_factory.mktemp("result-cache")))
        yield
