"""A run's results as JSON lines, one per file, appended as each file finishes: ``--resume RESULT.jsonl``.

A farm's shard may be killed at any point (a pre-empted pod, a CI time-out). Its
journal keeps what it finished: rerun with the same ``--resume RESULT.jsonl``, the
shard checks only the files not yet in it, and its output is the one an unbroken
run gives. ``affinity merge`` reads complete journals as it reads ``--format json``
results.

Layout (each line one compact JSON document)::

    {"schema": "quad-affinity-journal", "version": 1, "settings": {...}, "files": M,
     "run_digest": "...", "shard": {...} | null}                # the header: what the run checks
    {"index": i, "file": {...JSON file entry...}, "findings": [...JSON findings...]}   # one per file

``files`` and ``run_digest`` are the count and :func:`~affinity.shards.selection.run_digest` of the
files this run checks (a shard's files for ``--shard K/N``); ``index`` is a file's place among them.
The entries and findings are those of ``--format json`` (:mod:`affinity.output.json`), read back by
:mod:`affinity.shards.results`, so a resumed report writes every format as the first run's would.

Lines are appended and flushed one at a time, never rewritten: a run killed mid-line leaves one
partial last line, which the next run cuts off before it appends. A journal whose header names
other settings, another shard or another file list is refused with one line (it belongs to
another run); so is a damaged line before the last.
"""

from __future__ import annotations

import dataclasses
import io
import json
import os

from ..findings import FileReport
from ..settings import Settings
from .results import (
    CheckResult,
    ResultError,
    report_from_json,
    settings_from_json,
    shard_record_from_json,
    strict_json,
)
from .selection import ShardRecord

SCHEMA = "quad-affinity-journal"
VERSION = 1
#: A journal line longer than this is damage, not a file's findings (a 10M-finding file's line is ~2 GB).
LINE_BUDGET = 1 << 31


@dataclasses.dataclass
class Header:
    """What a journal's first line says about its run."""

    settings: dict
    files: int
    run_digest: str
    shard: dict | None

    def line(self) -> str:
        return _compact({"schema": SCHEMA, "version": VERSION, **dataclasses.asdict(self)})

    def differences(self, other: Header) -> list[str]:
        """The fields in which ``other`` names another run (``root``, the configuration's folder, aside)."""
        def comparable(h: Header) -> dict:
            return {**dataclasses.asdict(h), "settings": {k: v for k, v in h.settings.items() if k != "root"}}

        mine, theirs = comparable(self), comparable(other)
        return [key for key in mine if mine[key] != theirs[key]]


def header_of(settings: Settings, files: int, run_digest: str, shard: ShardRecord | None) -> Header:
    """The header of a run that checks ``files`` files (their list's digest ``run_digest``) with ``settings``."""
    as_json = json.loads(_compact(dataclasses.asdict(settings)))  # tuples as lists, as a journal holds them
    return Header(as_json, files, run_digest, None if shard is None else dataclasses.asdict(shard))


class Journal:
    """An open journal: :attr:`done` maps the index of each file it already holds to its report;
    :meth:`record` appends a finished file."""

    def __init__(self, path: str, header: Header):
        self.path = path
        self.header = header
        self.done: dict[int, FileReport] = {}
        found, end = _read(path)
        if found is not None:
            differ = header.differences(found[0])
            if differ:
                raise ResultError(f"written by another run (its {', '.join(differ)} differ); "
                                  "give a new --resume file or delete this one")
            self.done = found[1]
        self._out = open(path, "ab")  # append-only: what is there is never rewritten
        try:
            self._out.truncate(end)  # a partial last line (a run killed mid-write) is cut off
            if found is None:
                self._write(header.line())
        except BaseException:
            self._out.close()
            raise

    def record(self, index: int, report: FileReport, settings: Settings) -> None:
        """Append the file at ``index`` (its report, checked with ``settings``) and flush it to the system."""
        file, findings = json_of(report, settings)
        self._write(_compact({"index": index, "file": file, "findings": findings}))

    def _write(self, line: str) -> None:
        self._out.write(line.encode("utf-8") + b"\n")
        self._out.flush()

    def close(self) -> None:
        os.fsync(self._out.fileno())
        self._out.close()


def json_of(report: FileReport, settings: Settings) -> tuple[dict, list[dict]]:
    """``report``'s JSON file entry and findings, exactly as ``--format json`` writes them."""
    from ..output import CheckRun
    from ..output.json import write

    out = io.StringIO()
    write(CheckRun([report], settings), out)
    doc = json.loads(out.getvalue())
    return doc["files"][0], doc["findings"]


def read_journal(path: str) -> CheckResult:
    """A complete journal as the result ``affinity merge`` joins (:class:`ResultError` when it is not one)."""
    found, _ = _read(path)
    if found is None:
        raise ResultError("an empty journal (its run wrote nothing yet)")
    header, done = found
    if len(done) != header.files:
        raise ResultError(f"an unfinished journal: {len(done)} of its {header.files} files "
                          "(rerun its check with --resume to finish it)")
    try:
        shard = None if header.shard is None else shard_record_from_json(header.shard)
        settings = settings_from_json(header.settings)
    except (KeyError, TypeError, ValueError) as err:
        raise ResultError(f"a damaged journal header ({type(err).__name__}: {err})") from None
    return CheckResult(path=path, reports=[done[i] for i in range(header.files)], settings=settings, shard=shard,
                       truncated=False, baselined=0)


def _read(path: str) -> tuple[tuple[Header, dict[int, FileReport]] | None, int]:
    """The journal at ``path`` (None where it does not exist or holds no whole line) and the length of its
    whole lines: the offset the next line goes at. :class:`ResultError` names the first damaged line."""
    from ..loaders.regular import RefusedFile, open_regular

    try:
        f = open_regular(path)
    except FileNotFoundError:
        return None, 0
    except RefusedFile as err:
        raise ResultError(err.strerror) from None
    except OSError as err:
        raise ResultError(f"cannot read it: {err.strerror or err}") from None
    header, settings, done, end = None, None, {}, 0
    with f:
        for number, line in enumerate(iter(lambda: f.readline(LINE_BUDGET), b""), 1):
            if not line.endswith(b"\n"):
                if len(line) >= LINE_BUDGET:
                    raise ResultError(f"line {number} is longer than {LINE_BUDGET} bytes: not a journal")
                break  # the partial last line of a killed run
            doc = _parsed(line, number)
            if header is None:
                header, settings = _header(doc, number)
            else:
                index, report = _entry(doc, settings, header.files, number)
                done[index] = report
            end += len(line)
    return (None if header is None else (header, done)), end


def _parsed(line: bytes, number: int) -> dict:
    try:
        doc = strict_json(line.decode("utf-8"))
    except (ValueError, RecursionError) as err:
        raise ResultError(f"line {number}: not JSON ({type(err).__name__}: {str(err)[:80]})") from None
    if not isinstance(doc, dict):
        raise ResultError(f"line {number}: not a journal line")
    return doc


def _header(doc: dict, number: int) -> tuple[Header, Settings]:
    if doc.get("schema") != SCHEMA or doc.get("version") != VERSION:
        raise ResultError(f"line {number}: not an affinity check journal ({SCHEMA} version {VERSION}, "
                          "from --resume)")
    try:
        header = Header(doc["settings"], doc["files"], doc["run_digest"], doc["shard"])
        if type(header.files) is not int or header.files < 0:
            raise ValueError(f"files: {header.files!r}")
        return header, settings_from_json(header.settings)
    except (KeyError, TypeError, ValueError) as err:
        raise ResultError(f"line {number}: a damaged journal header ({type(err).__name__}: {err})") from None


def _entry(doc: dict, settings: Settings, files: int, number: int) -> tuple[int, FileReport]:
    try:
        index = doc["index"]
        if type(index) is not int or not 0 <= index < files:
            raise ValueError(f"index {index!r} is not one of the run's {files} files")
        return index, report_from_json(doc["file"], doc["findings"], settings)
    except (KeyError, TypeError, ValueError, AttributeError, IndexError) as err:
        raise ResultError(f"line {number}: a damaged file line ({type(err).__name__}: {err})") from None


def _compact(value) -> str:
    return json.dumps(value, separators=(",", ":"), allow_nan=False)
