"""The result cache's start-up costs: the tool fingerprint from source signatures, the cache folder
without platformdirs, BLAKE2 without OpenSSL; each still invalidates and resolves as before."""

from __future__ import annotations

import importlib.machinery
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import platformdirs
import pytest

from affinity.pipeline import cache


@pytest.fixture
def fake_packages(tmp_path, monkeypatch):
    """Source trees standing in for the installed ``affinity`` and ``render`` packages."""
    roots = {}
    for package, files in (("affinity", ("__init__.py", "sub/rules.py")), ("render", ("__init__.py",))):
        root = tmp_path / package
        for name in files:
            (root / name).parent.mkdir(parents=True, exist_ok=True)
            (root / name).write_text(f"# {name}\n")
        roots[package] = root

    def find_spec(name, package=None):
        spec = importlib.machinery.ModuleSpec(name, None, is_package=True)
        spec.submodule_search_locations = [str(roots[name])]
        return spec

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)
    return roots


def test_the_fingerprint_follows_every_source_edit(fake_packages):
    rules = fake_packages["affinity"] / "sub" / "rules.py"
    first = cache.tool_fingerprint()
    assert cache.tool_fingerprint() == first  # nothing changed: the same key, so cached reports are reused

    stat = rules.stat()
    rules.write_text("# rules.PY\n")  # same size, new content: the write moves the mtime
    os.utime(rules, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1))
    edited = cache.tool_fingerprint()
    assert edited != first

    stat = rules.stat()
    rules.write_text("# rules.py, longer\n")  # a longer file with the old mtime restored
    os.utime(rules, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    resized = cache.tool_fingerprint()
    assert resized not in (first, edited)

    (fake_packages["render"] / "new.py").write_text("")
    added = cache.tool_fingerprint()
    assert added not in (first, edited, resized)

    pycache = fake_packages["affinity"] / "__pycache__"
    pycache.mkdir()
    (pycache / "rules.cpython-311.pyc").write_bytes(b"\0")  # not a source
    assert cache.tool_fingerprint() == added


def test_the_fingerprint_lists_the_files_pathlib_finds(fake_packages):
    root = fake_packages["affinity"]
    (root / "deep" / "deeper").mkdir(parents=True)
    (root / "deep" / "deeper" / "x.py").write_text("x = 1\n")
    (root / "notes.txt").write_text("not python\n")
    found = {name for name, _ in cache._python_files(str(root))}
    assert found == {path.relative_to(root).as_posix() for path in root.rglob("*.py")}


@pytest.mark.skipif(os.name != "posix" or sys.platform == "darwin", reason="the XDG rule is worked out here")
@pytest.mark.parametrize("xdg", [None, "", "  ", "/tmp/xdg-cache"])
def test_the_cache_folder_is_platformdirs_choice(monkeypatch, xdg):
    monkeypatch.delenv("AFFINITY_CACHE_DIR", raising=False)
    if xdg is None:
        monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    else:
        monkeypatch.setenv("XDG_CACHE_HOME", xdg)
    assert cache.cache_folder() == platformdirs.user_cache_dir("quad-affinity", appauthor=False)


def test_blake2b_is_hashlibs():
    import hashlib

    data = bytes(range(256)) * 3
    assert cache.blake2b(data, digest_size=20).hexdigest() == hashlib.blake2b(data, digest_size=20).hexdigest()


def test_a_cached_check_loads_neither_openssl_nor_platformdirs(tmp_path):
    mesh = tmp_path / "quad.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    env = {k: v for k, v in os.environ.items() if k != "AFFINITY_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
    code = ("import sys; from affinity.cli import main\n"
            "try:\n    main(['check', sys.argv[1]])\nexcept SystemExit:\n    pass\n"
            "print(sorted({'_hashlib', 'platformdirs', 'tempfile'} & set(sys.modules)))")
    for _ in range(2):  # a fresh cache, then a hit
        out = subprocess.run([sys.executable, "-c", code, str(mesh)], env=env, capture_output=True, text=True,
                             check=True).stdout
        assert out.strip().splitlines()[-1] == "[]"
    assert (Path(env["XDG_CACHE_HOME"]) / "quad-affinity" / cache.DB_NAME).is_file()
