"""The result cache: an unchanged file's report comes back without reading the file again.

A report is stored under a key made of

- the content hash of the file and of everything it pulls in, recursively: the
  files of every role of the resource registry (:mod:`affinity.loaders.resources`:
  an OBJ's ``mtllib`` files, their texture maps, a USD layer's sublayers,
  references and payloads), read by the loaders' own readers;
- the path as given (reports name it) and the resolved settings of the file,
  and the USD reading options;
- the tool: its version and the names, sizes and modification times of the
  installed package's source files, since the version string does not change
  between commits (the signature Python's own bytecode cache trusts to tell
  whether a module changed; hashing the sources on every start cost more than
  the rest of a small check's cache look-up).

Content hashes are remembered per file under a pre-key (path, size, mtime_ns,
inode), so an unchanged file costs one ``stat`` and is not read; its list of
the files it names is kept with the resource roles it was read with (a role
registered since, and the file is read again). A file
modified in the last :data:`RACY_SECONDS` gets no pre-key (its mtime may not
yet tell two versions apart, as in git's "racy" index entries): it is hashed
again next time.

The cache is one SQLite file in the user cache folder (``platformdirs``' choice,
worked out here on Linux and other XDG systems, where importing it is most of
the cost), or in ``AFFINITY_CACHE_DIR``. It is an optimisation only: a folder that cannot be
written or a damaged database gives one warning line on stderr and the run goes
on (a damaged database is replaced by a new one). Reports that say more about
the run than about the file (``FileReport.transient``: an internal error, a
Dask worker that cannot see the path) are never stored. Entries unused for
:data:`MAX_AGE_DAYS` days go, and the oldest go first when the entries exceed
:data:`MAX_BYTES`.
"""

from __future__ import annotations

import dataclasses
import json
import os
import sqlite3
import sys
import time

from ..errors import MeshError
from ..findings import FileReport, report_from_bytes, report_to_bytes
from ..loaders.formats import format_named
from ..settings import Settings

try:  # the BLAKE2 module itself: hashlib would load OpenSSL first, a few ms of every start
    from _blake2 import blake2b
except ImportError:  # an interpreter built without it
    from hashlib import blake2b

#: Bump when the key or the stored report changes meaning.
SCHEMA = 1
DB_NAME = f"results-v{SCHEMA}.sqlite"
MAX_AGE_DAYS = 30
MAX_BYTES = 200_000_000
RACY_SECONDS = 2.0
#: Rows written between commits (one transaction per row would cost an fsync each).
COMMIT_EVERY = 200

_DAY = 86_400.0
_CHUNK = 1 << 20

_TABLES = """
CREATE TABLE IF NOT EXISTS files (path TEXT PRIMARY KEY, size INTEGER, mtime_ns INTEGER, inode INTEGER,
                                  digest TEXT, deps TEXT, used REAL);
CREATE TABLE IF NOT EXISTS results (key TEXT PRIMARY KEY, report BLOB, used REAL);
"""


def cache_folder() -> str:
    """``AFFINITY_CACHE_DIR``, else the user cache folder of quad-affinity."""
    folder = os.environ.get("AFFINITY_CACHE_DIR")
    if folder:
        return folder
    if os.name == "posix" and sys.platform != "darwin":  # platformdirs' XDG rule
        return os.path.join(os.environ.get("XDG_CACHE_HOME", "").strip() or os.path.expanduser("~/.cache"),
                            "quad-affinity")
    import platformdirs

    return platformdirs.user_cache_dir("quad-affinity", appauthor=False)


def tool_fingerprint() -> str:
    """The version, NumPy's version and the relative path, size and mtime_ns of every ``.py`` file
    of the ``affinity`` and ``render`` packages (an edit, a checkout or a reinstall changes them).

    ``render`` is found, not imported: ``affinity check`` never loads the renderer.
    """
    from importlib.util import find_spec

    import numpy as np

    from .. import __version__

    sources = []
    for package in ("affinity", "render"):
        for root in find_spec(package).submodule_search_locations:
            sources += [(f"{package}/{name}", *stat) for name, stat in _python_files(root)]
    signature = _json([__version__, np.__version__, sorted(sources)])
    return blake2b(signature.encode(), digest_size=20).hexdigest()


def _python_files(root: str, prefix: str = ""):
    """``(path relative to root, (size, mtime_ns))`` of every ``.py`` file under ``root``."""
    with os.scandir(root) as entries:
        for entry in entries:
            name = prefix + entry.name
            if entry.is_dir():
                yield from _python_files(entry.path, name + "/")
            elif entry.name.endswith(".py"):
                stat = entry.stat()
                yield name, (stat.st_size, stat.st_mtime_ns)


def _json(value) -> str:
    return json.dumps(value, sort_keys=True, separators=(",", ":"))


class ResultCache:
    """Reports by key in ``folder``; every failure is one warning line, then the cache is off.

    Use :meth:`key` then :meth:`get` before checking a file, :meth:`put` after,
    and :meth:`close` at the end of the run (commits and prunes).
    """

    def __init__(self, folder: str, tool: str | None = None):
        self.folder = folder
        self.tool = tool_fingerprint() if tool is None else tool
        self._db: sqlite3.Connection | None = None
        self._pending = 0
        self._damaged_entries = 0
        self._settings: dict[int, tuple[Settings, dict]] = {}  # id -> (the object, kept alive; its fields)
        self._now = time.time()
        path = os.path.join(folder, DB_NAME)
        try:
            self._db = self._open(path)
        except sqlite3.DatabaseError as err:  # not a database, or a damaged one
            if isinstance(err, sqlite3.OperationalError) and not os.path.isfile(path):
                self._warn(f"cannot open it ({err})")
                return
            self._warn(f"damaged ({err}); starting a new one", off=False)
            try:
                for suffix in ("", "-wal", "-shm"):
                    if os.path.exists(path + suffix):
                        os.remove(path + suffix)
                self._db = self._open(path)
            except (OSError, sqlite3.Error) as again:
                self._warn(f"cannot replace it ({again})")
        except OSError as err:
            self._warn(f"cannot create it ({err.strerror or err})")

    @staticmethod
    def _open(path: str) -> sqlite3.Connection:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        db = sqlite3.connect(path, timeout=10)
        try:
            db.execute("PRAGMA journal_mode=WAL")
            db.execute("PRAGMA synchronous=NORMAL")
            db.executescript(_TABLES)
            db.execute("SELECT count(*) FROM results").fetchone()
        except BaseException:
            db.close()
            raise
        return db

    def _warn(self, reason: str, off: bool = True) -> None:
        action = "; checking without it" if off else ""
        sys.stderr.write(f"affinity: warning: result cache {self.folder}: {reason}{action}\n")
        if off and self._db is not None:
            try:
                self._db.close()
            except sqlite3.Error:
                pass
            self._db = None

    @property
    def enabled(self) -> bool:
        return self._db is not None

    # -- keys -------------------------------------------------------------------------------------

    def key(self, path: str, settings: Settings, usd=None, source=None) -> str | None:
        """The key of ``path`` checked with ``settings``; None when the file cannot be hashed (no caching).

        ``source``, when given, is called for the file's bytes if they must be hashed (the
        file changed since its pre-key): ``lambda: data`` of a read the check then reuses.
        """
        if self._db is None:
            return None
        try:
            tree = self._tree(os.path.abspath(path), set(), source)
        except sqlite3.Error as err:
            self._warn(f"cannot read it ({err})")
            return None
        if tree is None:
            return None
        usd_key = None
        if os.path.splitext(path)[1].lower() in format_named("usd").suffixes:
            usd_key = [_usd_reader(), None if usd is None else dataclasses.asdict(usd)]
        if id(settings) not in self._settings:  # files share a few Settings objects: describe each once
            self._settings[id(settings)] = (settings, dataclasses.asdict(settings))
        payload = _json([SCHEMA, self.tool, path, tree, self._settings[id(settings)][1], usd_key])
        return blake2b(payload.encode(), digest_size=20).hexdigest()

    def _tree(self, path: str, seen: set[str], source=None) -> list | None:
        """``[path, digest, dependency trees...]``; None when ``path`` is not a readable file."""
        found = self._digest(path, source)
        if found is None:
            return None
        digest, deps = found
        seen.add(path)
        trees = [[dep, "cycle"] if dep in seen else self._tree(dep, seen) or [dep, "missing"] for dep in deps]
        return [path, digest, *trees]

    def _digest(self, path: str, source=None) -> tuple[str, list[str]] | None:
        """A file's content hash and the files it pulls in, from its pre-key when it is unchanged."""
        try:
            st = os.stat(path)
        except (OSError, ValueError):  # ValueError: a name with a NUL byte (an mtllib's), which no file has
            return None
        if not os.path.isfile(path):
            return None
        prekey = (st.st_size, st.st_mtime_ns, st.st_ino)
        row = self._db.execute("SELECT size, mtime_ns, inode, digest, deps FROM files WHERE path = ?",
                               (path,)).fetchone()
        readers = _readers()
        if row is not None and tuple(row[:3]) == prekey:
            stored = json.loads(row[4])
            if isinstance(stored, dict) and stored.get("readers") == readers:
                return row[3], stored["deps"]
        try:
            digest, deps = _hash_file(path, None if source is None else source())
        except (OSError, MeshError):
            return None
        if st.st_mtime_ns < (self._now - RACY_SECONDS) * 1e9:
            self._write("INSERT OR REPLACE INTO files VALUES (?, ?, ?, ?, ?, ?, ?)",
                        (path, *prekey, digest, _json({"readers": readers, "deps": deps}), self._now))
        return digest, deps

    # -- entries ----------------------------------------------------------------------------------

    def get(self, key: str | None) -> FileReport | None:
        """The stored report for ``key``, or None."""
        if key is None or self._db is None:
            return None
        try:
            row = self._db.execute("SELECT report, used FROM results WHERE key = ?", (key,)).fetchone()
        except sqlite3.Error as err:
            self._warn(f"cannot read it ({err})")
            return None
        if row is None:
            return None
        try:
            report = report_from_bytes(row[0])
        except ValueError as err:
            if not self._damaged_entries:
                self._warn(f"damaged entry ({err}); checking such files again", off=False)
            self._damaged_entries += 1
            self._write("DELETE FROM results WHERE key = ?", (key,))
            return None
        if row[1] < self._now - _DAY:
            self._write("UPDATE results SET used = ? WHERE key = ?", (self._now, key))
        return report

    def put(self, key: str | None, report: FileReport) -> None:
        """Store ``report`` under ``key``; transient reports (internal errors, unseen paths) are not stored."""
        if key is None or self._db is None or report.transient:
            return
        self._write("INSERT OR REPLACE INTO results VALUES (?, ?, ?)", (key, report_to_bytes(report), self._now))

    def _write(self, sql: str, values: tuple) -> None:
        if self._db is None:
            return
        try:
            self._db.execute(sql, values)
            self._pending += 1
            if self._pending >= COMMIT_EVERY:
                self._db.commit()
                self._pending = 0
        except sqlite3.Error as err:
            self._warn(f"cannot write it ({err})")

    def close(self) -> None:
        """Commit, drop entries unused for :data:`MAX_AGE_DAYS` and the oldest beyond :data:`MAX_BYTES`."""
        if self._db is None:
            return
        old = self._now - MAX_AGE_DAYS * _DAY
        try:
            self._db.execute("DELETE FROM results WHERE used < ?", (old,))
            self._db.execute("DELETE FROM files WHERE used < ?", (old,))
            self._db.execute(
                "DELETE FROM results WHERE key IN (SELECT key FROM (SELECT key, SUM(LENGTH(report)) "
                "OVER (ORDER BY used DESC, key) AS running FROM results) WHERE running > ?)", (MAX_BYTES,))
            self._db.commit()
            self._db.close()
        except sqlite3.Error as err:
            self._warn(f"cannot write it ({err})")
        self._db = None


def _readers() -> str:
    """What a file's stored dependencies were read with: the resource roles registered (a role
    registered later, e.g. a plug-in's normal map, must not be served an MTL file's old list)."""
    from ..loaders.resources import ROLES

    return _json(sorted((role.name, role.statement, role.named_in) for role in ROLES.values()))


def _hash_file(path: str, data: bytes | None = None) -> tuple[str, list[str]]:
    """The content hash of ``path`` (of its bytes ``data`` when given) and the absolute paths of
    the files it names (:func:`affinity.loaders.resources.named_files`)."""
    from ..loaders import reads_whole
    from ..loaders.resources import named_files

    if data is None and reads_whole(path):  # its references are read from the bytes: read them once
        with open(path, "rb") as fh:
            data = fh.read()
    if data is not None:
        digest = blake2b(data, digest_size=20)
    else:
        digest = blake2b(digest_size=20)
        with open(path, "rb") as fh:
            while chunk := fh.read(_CHUNK):
                digest.update(chunk)
    return digest.hexdigest(), [os.path.abspath(dep) for dep in named_files(path, data)]


def _usd_reader() -> str | None:
    """The usd-core version that would read a stage, None without one (found, not imported: that is slow)."""
    from importlib.metadata import PackageNotFoundError, version
    from importlib.util import find_spec

    if "pxr" in sys.modules and sys.modules["pxr"] is None:  # blocked, as a test does
        return None
    if find_spec("pxr") is None:
        return None
    try:
        return version("usd-core")
    except PackageNotFoundError:  # pxr from a USD build rather than the wheel
        return "pxr"
