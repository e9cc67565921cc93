"""Which files a run checks: the paths given, directories walked into their mesh files.

A directory is walked like ruff walks a project: below the paths given, folders
matching the ``exclude`` globs are not entered (by default ruff's folder names,
``.git``, ``.venv``, ``venv``, ``site-packages``, ``build``, ``dist``, ``.tox``,
``node_modules``, ``__pycache__`` and the like, see
:data:`~affinity.settings.DEFAULT_EXCLUDE`; the setting replaces them,
``extend-exclude`` adds to them), nor is any virtual environment (a folder
holding ``pyvenv.cfg`` or ``conda-meta/``, whatever its name), and files and
folders that the ``.gitignore`` files (at every level, and those above the walk
up to the repository root) or ``.git/info/exclude`` ignore are left out. Files
named explicitly are always checked, whatever their extension, so the loader can
say what is wrong with them; a configured ``exclude`` still drops them (a
pre-commit hook names every changed file), the default names do not.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Callable
from pathlib import Path

from ..errors import UsageError
from ..loaders.formats import MESH_SUFFIXES
from ..output.names import printable
from ..settings import Settings, glob_matches


def is_environment(folder: str) -> bool:
    """Whether ``folder`` is a Python virtual environment or a conda environment."""
    return os.path.isfile(os.path.join(folder, "pyvenv.cfg")) or os.path.isdir(os.path.join(folder, "conda-meta"))


class _Ignores:
    """The git ignore rules in force in one folder: (folder, pathspec) pairs, outermost first."""

    def __init__(self, specs: list[tuple[str, object]]):
        self.specs = specs

    @staticmethod
    def _read(path: str):
        import pathspec

        try:
            with open(path, encoding="utf-8", errors="replace") as fh:
                lines = fh.read().splitlines()
        except OSError:
            return None
        return pathspec.GitIgnoreSpec.from_lines(lines) if any(line.strip() for line in lines) else None

    @classmethod
    def above(cls, top: str) -> _Ignores:
        """The rules of the repository holding ``top``: ``.git/info/exclude`` and the ``.gitignore`` files above it."""
        top = os.path.abspath(top)
        chain = [top, *map(str, Path(top).parents)]
        root = next((folder for folder in chain if os.path.exists(os.path.join(folder, ".git"))), None)
        if root is None:
            return cls([])
        specs = []
        exclude = cls._read(os.path.join(root, ".git", "info", "exclude"))
        if exclude is not None:
            specs.append((root, exclude))
        for folder in reversed(chain[1 : chain.index(root) + 1]):
            spec = cls._read(os.path.join(folder, ".gitignore"))
            if spec is not None:
                specs.append((folder, spec))
        return cls(specs)

    def entering(self, folder: str) -> _Ignores:
        """The rules inside ``folder``: these and its own ``.gitignore``."""
        spec = self._read(os.path.join(folder, ".gitignore"))
        return self if spec is None else _Ignores([*self.specs, (os.path.abspath(folder), spec)])

    def ignores(self, path: str, is_dir: bool) -> bool:
        path = os.path.abspath(path)
        for folder, spec in self.specs:
            rel = os.path.relpath(path, folder).replace(os.sep, "/")
            if not rel.startswith("..") and spec.match_file(rel + "/" * is_dir):
                return True
        return False


def _excluded(settings: Settings, path: str, top: str) -> bool:
    """Whether an ``exclude``/``extend-exclude`` glob matches ``path`` (relative to the configuration, else to
    ``top``), or a default folder name matches it below ``top``, the folder the run was given."""
    below = os.path.relpath(path, top).replace(os.sep, "/")
    rel = settings.relative(path) or below
    return (any(glob_matches(pattern, rel) for pattern in settings.configured_exclude)
            or any(glob_matches(pattern, below) for pattern in settings.default_exclude))


def _to_check(path: str) -> bool:
    """Whether the walk hands ``path`` to the check: a regular file, or a FIFO, socket or device (the
    loader refuses those with one Q901 line naming them, as when they are named on the command line);
    not a broken link or a directory."""
    try:
        return not stat.S_ISDIR(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


def walk(top: str, settings_of: Callable[[str], Settings]) -> list[str]:
    """The mesh files under ``top``, sorted, with excluded folders, environments and git-ignored paths left out.

    ``settings_of(folder)`` gives the settings governing a folder (its ``exclude`` globs).
    """
    found: list[str] = []
    ignores = {os.path.abspath(top): _Ignores.above(top).entering(top)}
    for folder, dirs, files in os.walk(top):
        rules = ignores.pop(os.path.abspath(folder))
        settings = settings_of(folder)
        kept = []
        for name in sorted(dirs):
            sub = str(Path(folder, name))
            if _excluded(settings, sub, top) or is_environment(sub) or rules.ignores(sub, True):
                continue
            kept.append(name)
            ignores[os.path.abspath(sub)] = rules.entering(sub)
        dirs[:] = kept
        for name in sorted(files):
            path = str(Path(folder, name))
            if (os.path.splitext(name)[1].lower() in MESH_SUFFIXES and _to_check(path)
                    and not _excluded(settings, path, top) and not rules.ignores(path, False)):
                found.append(path)
    return sorted(found)


def collect_paths(paths: list[str], settings_of: Callable[[str], Settings] | None = None,
                  warn: Callable[[str], None] | None = None) -> list[str]:
    """Expand directories (see :func:`walk`) into their mesh files; ``["."]`` when ``paths`` is empty.

    A path that does not exist is a :class:`UsageError`. A directory with no mesh
    file is one too when it is all there is; among other paths it is a warning
    (``warn``) and the run goes on. A file reached several ways is kept once, under
    the first spelling (:func:`once_each`).
    """
    settings_of = settings_of or (lambda folder: Settings())
    paths = paths or [os.curdir]
    files: list[str] = []
    empty: list[str] = []
    for given in paths:
        if os.path.isdir(given):
            found = walk(given, settings_of)
            if not found:
                empty.append(given)
            files.extend(found)
        elif os.path.exists(given):
            files.append(given)
        else:
            raise UsageError(f"{printable(given)}: no such file or directory")
    for given in empty:
        message = f"{printable(given)}: no mesh files ({', '.join(MESH_SUFFIXES)}) in this directory"
        if not files:
            raise UsageError(message)
        if warn is not None:
            warn(f"warning: {message}")
    return once_each(files)


def once_each(files: list[str]) -> list[str]:
    """``files`` with every file once, under the first of its spellings: relative or absolute, with
    ``./`` or ``..``, through a symbolic link or a hard link (one file: one device and inode)."""
    seen: set = set()
    kept = []
    for path in files:
        try:
            st = os.stat(path)
        except (OSError, ValueError):  # gone since it was found: the check says so, under this name
            identity = os.path.abspath(path)
        else:  # a file system without inode numbers (0) falls back to the resolved path
            identity = (st.st_dev, st.st_ino) if st.st_ino else os.path.realpath(path)
        if identity not in seen:
            seen.add(identity)
            kept.append(path)
    return kept


def file_size(path: str) -> int:
    """The size of the file at ``path`` in bytes, 0 where it cannot be seen (it is reported when checked)."""
    try:
        return os.path.getsize(path)
    except OSError:
        return 0
