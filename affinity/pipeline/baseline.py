"""Baselines: accept the findings an asset has today, fail only on new ones.

A baseline records, per (file, group/object, rule), how many findings there
were: never face indices or lines, so reordering faces or editing other parts
of the file does not bring known findings back. Paths are relative to the
baseline file's folder, so the baseline can be committed next to the assets.

Only findings beyond the recorded count are new. Which of a key's findings are
shown as the new ones is decided by their measured values: the baseline also
keeps each finding's value (:func:`affinity.output.value_token`, independent of
face order), and findings whose value it does not know come first. File layout::

    {"schema": "quad-affinity-baseline", "version": 1,
     "entries": [{"path": "props/crate.obj", "group": "lid", "code": "Q101",
                  "count": 2, "values": ["3.25", "7.5"]}, ...]}
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections import Counter

import numpy as np

from ..atomic import atomic_write
from ..errors import UsageError
from ..findings import FileReport, RuleHits
from ..output import group_name, value_token
from ..output.names import printable

SCHEMA = "quad-affinity-baseline"
VERSION = 1

#: (path relative to the baseline's folder, group name, rule code)
Key = tuple[str, str, str]


@dataclasses.dataclass
class Baseline:
    """Known findings: per key, their count and their value tokens."""

    folder: str
    counts: dict[Key, int]
    values: dict[Key, list[str]]


def _relative(path: str, folder: str) -> str:
    return os.path.relpath(os.path.abspath(path), folder).replace(os.sep, "/")


def _keyed_rows(report: FileReport, folder: str):
    """Yield ``(key, hits, rows)`` for every (group, rule) of a report; rows index into ``hits``."""
    path = _relative(report.path, folder)
    for hits in report.hits:
        for g in np.unique(hits.groups).tolist():
            yield (path, group_name(report, g), hits.code), hits, np.flatnonzero(hits.groups == g)


def record(reports: list[FileReport], baseline_path: str) -> Baseline:
    """A baseline holding every finding of ``reports``."""
    folder = os.path.dirname(os.path.abspath(baseline_path))
    counts: dict[Key, int] = {}
    values: dict[Key, list[str]] = {}
    for report in reports:
        for key, hits, rows in _keyed_rows(report, folder):
            counts[key] = counts.get(key, 0) + len(rows)
            values.setdefault(key, []).extend(value_token(v) for v in hits.values[rows].tolist())
    return Baseline(folder, counts, values)


def write(baseline: Baseline, path: str) -> None:
    """Write ``baseline`` to ``path`` atomically, entries sorted so diffs stay small."""
    entries = [
        {"path": p, "group": g, "code": c, "count": baseline.counts[(p, g, c)],
         "values": sorted(baseline.values.get((p, g, c), []), key=float)}
        for p, g, c in sorted(baseline.counts)
    ]
    try:
        with atomic_write(path) as f:
            json.dump({"schema": SCHEMA, "version": VERSION, "entries": entries}, f, indent=1)
            f.write("\n")
    except OSError as err:
        raise UsageError(f"{printable(path)}: cannot write the baseline: {err.strerror or err}") from None


def read(path: str) -> Baseline:
    """Read a baseline file; anything unreadable or malformed is a :class:`UsageError`."""
    try:
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
        if doc.get("schema") != SCHEMA or doc.get("version") != VERSION:
            raise ValueError(f"not a {SCHEMA} version {VERSION} file")
        counts: dict[Key, int] = {}
        values: dict[Key, list[str]] = {}
        for entry in doc["entries"]:
            key = (str(entry["path"]), str(entry["group"]), str(entry["code"]))
            counts[key] = int(entry["count"])
            values[key] = [value_token(float(v)) for v in entry.get("values", [])]
    except OSError as err:
        raise UsageError(f"{printable(path)}: cannot read the baseline: {err.strerror or err}") from None
    except (ValueError, KeyError, TypeError, AttributeError) as err:
        raise UsageError(f"{printable(path)}: not a valid baseline file: {err}") from None
    return Baseline(os.path.dirname(os.path.abspath(path)), counts, values)


def _new_rows(hits: RuleHits, rows: np.ndarray, known: int, known_values: list[str]) -> np.ndarray:
    """The ``len(rows) - known`` rows shown as new: values the baseline does not know first."""
    n_new = len(rows) - known
    if n_new <= 0:
        return rows[:0]
    if known == 0:
        return rows
    unclaimed = Counter(known_values)
    unknown, familiar = [], []
    for row, token in zip(rows.tolist(), (value_token(v) for v in hits.values[rows].tolist())):
        if unclaimed[token] > 0:
            unclaimed[token] -= 1
            familiar.append(row)
        else:
            unknown.append(row)
    return np.sort(np.array((unknown + familiar)[:n_new], dtype=np.int64))


def apply(reports: list[FileReport], baseline: Baseline) -> tuple[list[FileReport], dict[str, int]]:
    """Drop the known findings.

    Returns
    -------
    reports : the reports with only their new findings
    baselined : path -> number of findings the baseline hid
    """
    kept_reports, baselined = [], {}
    for report in reports:
        keep = {id(hits): np.zeros(len(hits), dtype=bool) for hits in report.hits}
        hidden = 0
        for key, hits, rows in _keyed_rows(report, baseline.folder):
            new = _new_rows(hits, rows, baseline.counts.get(key, 0), baseline.values.get(key, []))
            keep[id(hits)][new] = True
            hidden += len(rows) - len(new)
        hits = [
            h.subset(m)
            for h in report.hits
            if (m := keep[id(h)]).any()
        ]
        kept_reports.append(dataclasses.replace(report, hits=hits))
        baselined[report.path] = hidden
    return kept_reports, baselined
