"""JSON output (schema ``quad-affinity-check``, version 1).

Document layout::

    {
      "schema": "quad-affinity-check", "version": 1,
      "settings": {...resolved settings...},
      "files": [{"path", "faces", "quads", "triangles", "ngons", "findings"}
                | {"path", "error", "line"} | {"path", "skipped"}],
      "findings": [{"path", "line", "column", "code", "name", "face", "value",
                    "threshold", "group", "message"}],
      "summary": {"files", "checked", "unreadable", "skipped", "findings",
                  "by_rule": {"Q101": n, ...}}
    }

``face`` is the 0-based index of the face in file order counting every face;
``line`` its 1-based source line (0 in binary PLY); ``value`` the measured score
in the rule's unit, ``threshold`` the limit it exceeded.
"""

from __future__ import annotations

import dataclasses
import json
from typing import TextIO

from ..findings import FileReport
from ..settings import Settings
from . import file_findings, rule_counts

SCHEMA = "quad-affinity-check"
VERSION = 1


def _file_entry(report: FileReport) -> dict:
    if report.error is not None:
        return {"path": report.path, "error": report.error, "line": report.error_line}
    if report.skipped is not None:
        return {"path": report.path, "skipped": report.skipped}
    return {"path": report.path, **report.counts, "findings": report.n_findings}


def document(reports: list[FileReport], settings: Settings) -> dict:
    """The whole JSON document as Python objects."""
    findings = [dataclasses.asdict(f) for r in reports for f in file_findings(r)[0]]
    unreadable = sum(r.error is not None for r in reports)
    skipped = sum(r.skipped is not None for r in reports)
    return {
        "schema": SCHEMA,
        "version": VERSION,
        "settings": dataclasses.asdict(settings),
        "files": [_file_entry(r) for r in reports],
        "findings": findings,
        "summary": {
            "files": len(reports),
            "checked": len(reports) - unreadable - skipped,
            "unreadable": unreadable,
            "skipped": skipped,
            "findings": len(findings),
            "by_rule": rule_counts(reports),
        },
    }


def write(reports: list[FileReport], settings: Settings, out: TextIO) -> None:
    json.dump(document(reports, settings), out, indent=1)
    out.write("\n")
