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

Content hashes are remembered per file under its signature (size, mtime_ns,
ctime_ns, inode, device), so an unchanged file costs one ``stat`` and is not
read. The ctime moves with every write and cannot be set back, so an in-place
edit that keeps the size and restores the mtime is still seen. A file's list of
the files it names is kept with the resource roles it was read with (a role
registered since, and the file is read again). A file changed in the last
:data:`RACY_SECONDS` gets no stored signature (its clock may not yet tell two
versions apart, as in git's "racy" index entries): it is hashed again next time.

A report is stored only when it belongs to its key: the key is made from the
files as they were before the check read them, so after the check every file of
the key is stat-ed again, and the report is dropped when any signature moved (a
file swapped while a worker was reading it, or created or deleted since). A
racy file (one whose clock cannot tell a second edit in the same tick) is
hashed again instead, and the report is dropped when its content moved.

The cache is one SQLite file in the user cache folder (``platformdirs``' choice,
worked out here on Linux and other XDG systems, where importing it is most of
the cost), or in ``AFFINITY_CACHE_DIR``. Its name carries a digest of the table
layout (:data:`DB_NAME`), and a database whose tables are not laid out so is
not read, so versions of the tool that store rows differently never read each
other's rows. It is an optimisation only, and everything read from it is checked
before use: a row's types, its checksum (BLAKE2 over the whole row), the
report's magic and its JSON. A row that fails is a miss (the file is checked
again and the row rewritten), and a database that SQLite finds damaged, or that
fails its ``quick_check`` after a damaged row, is set aside as
``NAME.damaged`` and rebuilt, with this run's reports. A folder that cannot be
written gives one warning line on stderr and the run goes on without the cache.
A run writes at most one warning line about its cache, naming the file. Reports
that say more about the run than about the file (``FileReport.transient``: an
internal error, a Dask worker that cannot see the path) are never stored.
Entries unused for :data:`MAX_AGE_DAYS` days go, and the oldest go first when the
entries exceed :data:`MAX_BYTES`; so do the files of other layouts (other versions of
the tool) and set-aside ones that nothing has written for as long.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import sqlite3
import stat
import sys
import time

from ..errors import MeshError
from ..findings import FileReport, report_from_bytes, report_to_bytes
from ..loaders.formats import format_named
from ..output.names import printable
from ..settings import Settings

try:  # the BLAKE2 module itself: hashlib would load OpenSSL first, a few ms of every start
    from _blake2 import blake2b
except ImportError:  # an interpreter built without it
    from hashlib import blake2b

#: Bump when the key or the stored report changes meaning (a change of the tables changes DB_NAME by itself).
SCHEMA = 2
MAX_AGE_DAYS = 30
MAX_BYTES = 200_000_000
RACY_SECONDS = 2.0
#: Rows written between commits (one transaction per row would cost an fsync each).
COMMIT_EVERY = 200

_DAY = 86_400.0
_CHUNK = 1 << 20

#: The tables, exactly as SQLite keeps their statements in ``sqlite_master``. WITHOUT ROWID: one
#: b-tree a table, keyed by the primary key, so no separate index can disagree with its table (a
#: damaged index entry made an INSERT OR REPLACE add a second row for one path, which SQLite
#: reported as a malformed database only in the run after).
_TABLES = {
    "files": "CREATE TABLE files (path BLOB PRIMARY KEY, size INTEGER, mtime_ns INTEGER, ctime_ns INTEGER, "
             "inode INTEGER, device INTEGER, digest TEXT, deps TEXT, used REAL, checksum TEXT) WITHOUT ROWID",
    "results": "CREATE TABLE results (key TEXT PRIMARY KEY, report BLOB, used REAL, checksum TEXT) WITHOUT ROWID",
}
_LAYOUT = blake2b(json.dumps([SCHEMA, _TABLES], sort_keys=True).encode(), digest_size=4).hexdigest()
DB_NAME = f"results-v{SCHEMA}-{_LAYOUT}.sqlite"
DAMAGED_SUFFIX = ".damaged"
#: What a call into SQLite raises: its errors, and a UnicodeDecodeError when Python decodes an error
#: message quoting damaged bytes of the schema.
_DATABASE_ERRORS = (sqlite3.Error, UnicodeDecodeError)


def db_name(shard=None) -> str:
    """The database's file name: :data:`DB_NAME`, or for shard K of N (``--shard K/N``) a file of its own, so
    the workers of a farm never write one database over network storage.

    >>> db_name()[-7:], db_name("2/8").endswith("-shard-2-of-8.sqlite")
    ('.sqlite', True)
    """
    if shard is None:
        return DB_NAME
    index, count = str(shard).split("/")
    return DB_NAME.replace(".sqlite", f"-shard-{index}-of-{count}.sqlite")


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


def _checksum(key: str | bytes, data: str | bytes) -> str:
    """A row's checksum: BLAKE2 of its ``data`` keyed with its primary key (at most 64 bytes of it, the
    rest hashed in), so a row moved under another key fails too."""
    key = key.encode("utf-8", "surrogateescape") if isinstance(key, str) else key
    data = data.encode("utf-8", "surrogateescape") if isinstance(data, str) else data
    return blake2b(key[64:] + b"\0" + data, key=key[:64], digest_size=16).hexdigest()


def _file_checksum(name: bytes, signature: tuple, digest: str, deps: str) -> str:
    """The checksum of a ``files`` row (ASCII JSON of its fields: the same text on every Python)."""
    return _checksum(name, json.dumps([*signature, digest, deps]))


def _signature(st: os.stat_result) -> tuple[int, int, int, int, int]:
    """What tells a file's versions apart without reading it: (size, mtime_ns, ctime_ns, inode, device)."""
    return st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino, st.st_dev


class _DamagedRow(ValueError):
    """A row that fails its checks: wrong types, checksum, magic or JSON."""


class ResultCache:
    """Reports by key in ``folder``; at most one warning line a run, and the run never fails.

    Use :meth:`key` then :meth:`get` before checking a file, :meth:`put` after,
    and :meth:`close` at the end of the run (commits and prunes).
    """

    def __init__(self, folder: str, tool: str | None = None, shard=None):
        self.folder = folder
        self.path = os.path.join(folder, db_name(shard))
        self.tool = tool_fingerprint() if tool is None else tool
        self._db: sqlite3.Connection | None = None
        self._pending = 0
        self._warned = False
        self._damaged_rows = 0
        self._set_aside_once = False
        self._settings: dict[int, tuple[Settings, dict]] = {}  # id -> (the object, kept alive; its fields)
        self._read: dict[str, list[tuple[str, tuple | None, str | None]]] = {}  # key -> the files it hashed
        self._kept: dict[str, FileReport] = {}  # this run's reports by key, to rebuild a damaged database
        self._now = time.time()
        try:
            self._db = self._open(self.path)
        except _DATABASE_ERRORS as err:
            if _is_damage(err):
                self._set_aside(err)
            else:
                self._warn(f"cannot open it ({err})")
        except OSError as err:
            self._warn(f"cannot create it ({err.strerror or err})")

    @staticmethod
    def _open(path: str) -> sqlite3.Connection:
        """The database at ``path``, created when new; DatabaseError when its tables are not :data:`_TABLES`."""
        os.makedirs(os.path.dirname(path), exist_ok=True)
        db = sqlite3.connect(path, timeout=10)
        db.text_factory = _text  # damaged text is a row that fails its checks, not an error of the whole file
        try:
            db.execute("PRAGMA journal_mode=WAL")
            db.execute("PRAGMA synchronous=NORMAL")
            db.execute("PRAGMA cell_size_check=ON")  # a damaged page is an error, not a wrong row
            tables = _tables(db)
            if not tables:
                with db:
                    db.execute("BEGIN IMMEDIATE")  # two runs creating the tables at once: one waits for the other
                    tables = _tables(db)
                    for statement in [] if tables else _TABLES.values():
                        db.execute(statement)
                tables = tables or _TABLES
            if tables != _TABLES:
                raise sqlite3.DatabaseError("its tables are not those of this version")
        except BaseException:
            db.close()
            raise
        return db

    def _warn(self, reason: str, off: bool = True) -> None:
        """One warning line a run (the first problem); ``off`` also closes the cache for the rest of it."""
        if not self._warned:
            action = "; checking without it" if off else ""
            sys.stderr.write(f"affinity: warning: result cache {printable(self.path)}: {reason}{action}\n")
            self._warned = True
        if off:
            self._close_quietly()

    def _close_quietly(self) -> None:
        if self._db is not None:
            try:
                self._db.close()
            except _DATABASE_ERRORS:
                pass
            self._db = None

    def _set_aside(self, err: Exception) -> None:
        """Rename the damaged database (and its journal) to ``NAME.damaged`` and start a new one holding
        this run's reports; once a run (a second failure turns the cache off)."""
        self._close_quietly()
        if self._set_aside_once:
            self._warn(f"damaged again ({err})")
            return
        self._set_aside_once = True
        name = os.path.basename(self.path)
        self._warn(f"damaged ({err}); set aside as {name}{DAMAGED_SUFFIX}, starting a new one", off=False)
        try:
            for suffix in ("", "-wal", "-shm"):
                if os.path.exists(self.path + suffix):
                    os.replace(self.path + suffix, self.path + DAMAGED_SUFFIX + suffix)
            self._db = self._open(self.path)
        except (OSError, *_DATABASE_ERRORS) as again:
            self._warn(f"cannot replace it ({again})")
            return
        for key, report in self._kept.items():
            self._store(key, report)

    def _failed(self, err: Exception, doing: str) -> None:
        """A database call failed: damage sets the file aside; anything else (locked, full, read-only)
        ends the cache for this run."""
        if _is_damage(err):
            self._set_aside(err)
        else:
            self._warn(f"cannot {doing} it ({err})")

    def _damaged(self, err: ValueError) -> None:
        """A row that failed its checks: one warning, the row dropped; :meth:`close` checks the whole file."""
        self._damaged_rows += 1
        self._warn(f"damaged entry ({err}); checking such files again", off=False)

    def _fetch(self, sql: str, values: tuple) -> tuple | None:
        if self._db is None:
            return None
        try:
            return self._db.execute(sql, values).fetchone()
        except _DATABASE_ERRORS as err:
            self._failed(err, "read")
            return None

    @property
    def enabled(self) -> bool:
        return self._db is not None

    # -- keys -------------------------------------------------------------------------------------

    def key(self, path: str, settings: Settings, usd=None, source=None) -> str | None:
        """The key of ``path`` checked with ``settings``; None when the file cannot be hashed (no caching).

        ``source``, when given, is called for the file's bytes if they must be hashed (the
        file changed since its signature was stored): ``lambda: data`` of a read the check then reuses.
        """
        if self._db is None:
            return None
        read: list[tuple[str, tuple | None, str | None]] = []
        tree = self._tree(os.path.abspath(path), set(), read, source)
        if tree is None or self._db is None:
            return None
        usd_key = None
        if os.path.splitext(path)[1].lower() in format_named("usd").suffixes:
            usd_key = [_usd_reader(), None if usd is None else dataclasses.asdict(usd)]
        elif os.path.splitext(path)[1].lower() in format_named("fbx").suffixes:  # the uv set is a scene option
            usd_key = [_reader_version("ufbx", "ufbx"), None if usd is None else dataclasses.asdict(usd)]
        if id(settings) not in self._settings:  # files share a few Settings objects: describe each once
            self._settings[id(settings)] = (settings, dataclasses.asdict(settings))
        payload = _json([SCHEMA, self.tool, path, tree, self._settings[id(settings)][1], usd_key])
        key = blake2b(payload.encode(), digest_size=20).hexdigest()
        self._read[key] = read
        return key

    def _tree(self, path: str, seen: set[str], read: list, source=None) -> list | None:
        """``[path, digest, dependency trees...]``; None when ``path`` is not a readable file.

        Appends ``(path, signature, digest of a racy file)`` to ``read`` for every file
        hashed, and ``(path, None, None)`` for every missing one.
        """
        found = self._digest(path, read, source)
        if found is None:
            return None
        digest, deps = found
        seen.add(path)
        trees = []
        for dep in deps:
            if dep in seen:
                trees.append([dep, "cycle"])
                continue
            tree = self._tree(dep, seen, read)
            if tree is None:
                read.append((dep, None, None))
            trees.append(tree or [dep, "missing"])
        return [path, digest, *trees]

    def _digest(self, path: str, read: list, source=None) -> tuple[str, list[str]] | None:
        """A file's content hash and the files it pulls in, from its stored signature when it is unchanged."""
        try:
            st = os.stat(path)
        except (OSError, ValueError):  # ValueError: a name with a NUL byte (an mtllib's), which no file has
            return None
        if not stat.S_ISREG(st.st_mode):
            return None
        signature = _signature(st)
        racy = max(st.st_mtime_ns, st.st_ctime_ns) >= (self._now - RACY_SECONDS) * 1e9
        readers = _readers()
        found = None if racy else self._stored_digest(path, signature, readers)
        if found is None:
            try:
                found = _hash_file(path, None if source is None else source())
            except (OSError, MeshError):
                return None
            if not racy:
                deps = _json({"readers": readers, "deps": found[1]})
                self._write("INSERT OR REPLACE INTO files VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                            (os.fsencode(path), *signature, found[0], deps, self._now,
                             _file_checksum(os.fsencode(path), signature, found[0], deps)))
        # A racy file is hashed again before its report is stored, unless the check parses the very
        # bytes hashed here (``source``).
        read.append((path, signature, found[0] if racy and source is None else None))
        return found

    def _stored_digest(self, path: str, signature: tuple, readers: str) -> tuple[str, list[str]] | None:
        """The stored hash and dependencies of ``path`` when its row has ``signature`` and passes its checks."""
        name = os.fsencode(path)
        row = self._fetch("SELECT size, mtime_ns, ctime_ns, inode, device, digest, deps, checksum FROM files "
                          "WHERE path = ?", (name,))
        if row is None or tuple(row[:5]) != signature:
            return None  # a new or changed file (or a damaged signature: the same outcome)
        digest, deps, checksum = row[5:]
        try:
            if not (isinstance(digest, str) and isinstance(deps, str) and isinstance(checksum, str)
                    and checksum == _file_checksum(name, signature, digest, deps)):
                raise _DamagedRow("a file's row fails its checksum")
            stored = json.loads(deps)
        except ValueError as err:
            self._damaged(err)
            return None
        names = stored.get("deps") if isinstance(stored, dict) else None
        if not isinstance(names, list) or not all(isinstance(name, str) for name in names):
            self._damaged(_DamagedRow("a file's row holds no list of files"))
            return None
        if stored.get("readers") != readers:
            return None  # read with other resource roles: read again
        return digest, names

    # -- entries ----------------------------------------------------------------------------------

    def get(self, key: str | None) -> FileReport | None:
        """The stored report for ``key``, or None (also for a row that fails its checks, then dropped)."""
        row = None if key is None else self._fetch("SELECT report, used, checksum FROM results WHERE key = ?", (key,))
        if row is None:
            return None
        blob, used, checksum = row
        try:
            if not (isinstance(blob, bytes) and isinstance(checksum, str) and checksum == _checksum(key, blob)):
                raise _DamagedRow("a report's row fails its checksum")
            report = report_from_bytes(blob)
        except ValueError as err:
            self._damaged(err)
            self._write("DELETE FROM results WHERE key = ?", (key,))
            return None
        if not isinstance(used, (int, float)) or used < self._now - _DAY:
            self._write("UPDATE results SET used = ? WHERE key = ?", (self._now, key))
        self._kept[key] = report
        self._read.pop(key, None)
        return report

    def put(self, key: str | None, report: FileReport) -> None:
        """Store ``report`` under ``key`` when every file the key hashed is as it was (see the module
        docstring); transient reports (internal errors, unseen paths) are not stored."""
        if key is None or self._db is None or report.transient:
            return
        read = self._read.pop(key, None)
        if read is None or not _unchanged(read):
            return
        self._kept[key] = report
        self._store(key, report)

    def _store(self, key: str, report: FileReport) -> None:
        blob = report_to_bytes(report)
        self._write("INSERT OR REPLACE INTO results VALUES (?, ?, ?, ?)", (key, blob, self._now, _checksum(key, blob)))

    def _write(self, sql: str, values: tuple) -> None:
        if self._db is None:
            return
        try:
            self._db.execute(sql, values)
            self._pending += 1
            if self._pending >= COMMIT_EVERY:
                self._db.commit()
                self._pending = 0
        except _DATABASE_ERRORS as err:
            self._failed(err, "write")

    def close(self) -> None:
        """Commit, drop entries unused for :data:`MAX_AGE_DAYS` and the oldest beyond :data:`MAX_BYTES`;
        after a damaged row, set the file aside when SQLite's ``quick_check`` fails."""
        if self._damaged_rows and self._fetch("PRAGMA quick_check", ()) != ("ok",) and self._db is not None:
            self._set_aside(sqlite3.DatabaseError("quick_check failed"))
        old = self._now - MAX_AGE_DAYS * _DAY
        for _ in range(2):  # once more on the rebuilt database, should this one turn out damaged
            if self._db is None:
                return
            try:
                self._db.execute("DELETE FROM results WHERE used < ?", (old,))
                self._db.execute("DELETE FROM files WHERE used < ?", (old,))
                self._db.execute(
                    "DELETE FROM results WHERE key IN (SELECT key FROM (SELECT key, SUM(LENGTH(report)) "
                    "OVER (ORDER BY used DESC, key) AS running FROM results) WHERE running > ?)", (MAX_BYTES,))
                self._db.commit()
                break
            except _DATABASE_ERRORS as err:
                self._failed(err, "write")
        self._close_quietly()
        self._remove_unused_files(old)

    def _remove_unused_files(self, old: float) -> None:
        """Delete the databases of other layouts (other versions of the tool) and set-aside ones that
        nothing has written for :data:`MAX_AGE_DAYS` days: an upgrade must not leave 200 MB behind for good."""
        name = os.path.basename(self.path)
        ours = {name, f"{name}-wal", f"{name}-shm"}
        try:
            with os.scandir(self.folder) as entries:
                unused = [entry.path for entry in entries if entry.name.startswith("results-v")
                          and ".sqlite" in entry.name and entry.name not in ours
                          and entry.stat(follow_symlinks=False).st_mtime < old]
        except OSError:
            return
        for path in unused:
            with contextlib.suppress(OSError):
                os.remove(path)


def _text(data: bytes) -> str:
    """A TEXT value as stored; bytes that are not UTF-8 (a flipped bit) kept as surrogates, never raised."""
    return data.decode("utf-8", "surrogateescape")


def _tables(db: sqlite3.Connection) -> dict[str, str]:
    """Table name -> its CREATE statement, as SQLite keeps them."""
    return dict(db.execute("SELECT name, sql FROM sqlite_master WHERE type = 'table'").fetchall())


def _is_damage(err: Exception) -> bool:
    """Whether SQLite says the file is damaged or no database (SQLITE_CORRUPT, SQLITE_NOTADB), rather than
    locked, full or read-only: Python raises the plain DatabaseError for exactly those, and a
    UnicodeDecodeError when the message quotes damaged schema text."""
    return type(err) is sqlite3.DatabaseError or isinstance(err, UnicodeDecodeError)


def _unchanged(read: list[tuple[str, tuple | None, str | None]]) -> bool:
    """Whether every file a key hashed still has the signature (and a racy one the content) it had then,
    and every missing one is still missing."""
    for path, signature, racy_digest in read:
        try:
            st = os.stat(path)
        except (OSError, ValueError):
            if signature is None:
                continue
            return False
        if signature is None or _signature(st) != signature:
            return False
        try:
            if racy_digest is not None and _content_digest(path) != racy_digest:
                return False
        except OSError:
            return False
    return True


def _readers() -> str:
    """What a file's stored dependencies were read with: the resource roles registered (a role
    registered later, e.g. a plug-in's normal map, must not be served an MTL file's old list)."""
    from ..loaders.resources import ROLES

    return _json(sorted((role.name, role.statement, role.named_in) for role in ROLES.values()))


def _hash_file(path: str, data: bytes | None = None) -> tuple[str, list[str]]:
    """The content hash of ``path`` (of its bytes ``data`` when given) and the absolute paths of
    the files it names (:func:`affinity.loaders.references.named_files`)."""
    from ..loaders import reads_whole
    from ..loaders.references import named_files

    if data is None and reads_whole(path):  # its references are read from the bytes: read them once
        with open(path, "rb") as fh:
            data = fh.read()
    digest = blake2b(data, digest_size=20).hexdigest() if data is not None else _content_digest(path)
    return digest, [os.path.abspath(dep) for dep in named_files(path, data)]


def _content_digest(path: str) -> str:
    """BLAKE2 of the file's bytes, read in chunks."""
    digest = blake2b(digest_size=20)
    with open(path, "rb") as fh:
        while chunk := fh.read(_CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def _usd_reader() -> str | None:
    """The usd-core version that would read a stage, None without one (found, not imported: that is slow)."""
    return _reader_version("pxr", "usd-core")


def _reader_version(module: str, distribution: str) -> str | None:
    """The version of ``distribution`` whose ``module`` would read a file, None without the module (found, not
    imported: that may be slow); the module's name when it comes from elsewhere (pxr from a USD build)."""
    from importlib.metadata import PackageNotFoundError, version
    from importlib.util import find_spec

    if module in sys.modules and sys.modules[module] is None:  # blocked, as a test does
        return None
    if find_spec(module) is None:
        return None
    try:
        return version(distribution)
    except PackageNotFoundError:
        return module
