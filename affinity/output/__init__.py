"""Output formats for ``affinity check``: one module per format, each with ``write(run, out)``.

``text`` (ruff-style lines), ``json`` (the documented schema), ``sarif`` (SARIF
2.1.0 for code scanning), ``github`` (workflow annotations) and ``junit`` (XML
for CI test reports). This package holds what they share: the flat
:class:`Finding` rows and how a finding is described.
"""

from __future__ import annotations

import importlib
import os
from dataclasses import dataclass

import numpy as np

from ..findings import FileReport, RuleHits
from ..rules import RULES, with_unit
from ..settings import Settings

FORMATS = ("text", "json", "sarif", "github", "junit")


@dataclass
class CheckRun:
    """Everything a format writes: the reports (in file order) and how they were produced.

    ``settings`` are the resolved settings for the working directory (files
    governed by another configuration file have their own); ``baselined`` maps a
    path to the number of its findings a baseline hid (None: no baseline was used).
    """

    reports: list[FileReport]
    settings: Settings
    baselined: dict[str, int] | None = None

    def tally(self) -> dict[str, int]:
        """Counts for a summary: ``files``, ``checked``, ``unreadable``, ``skipped``, ``findings``, ``baselined``."""
        unreadable = sum(r.error is not None for r in self.reports)
        skipped = sum(r.skipped is not None for r in self.reports)
        return {
            "files": len(self.reports),
            "checked": len(self.reports) - unreadable - skipped,
            "unreadable": unreadable,
            "skipped": skipped,
            "findings": sum(r.n_findings for r in self.reports),
            "baselined": sum((self.baselined or {}).values()),
        }


@dataclass(frozen=True)
class Finding:
    """One finding, as every structured format carries it (design.md, "Rule codes").

    In a USD stage, ``prim`` is the mesh prim's path, ``face`` counts within that
    prim, and ``line``/``column`` are 0; ``prim`` is None in other formats and for
    file-level findings.
    """

    path: str
    line: int
    column: int
    code: str
    name: str
    face: int
    value: float
    threshold: float | None
    group: str
    message: str
    prim: str | None = None


def writer(name: str):
    """The ``write(run, out)`` function of a format, imported only when asked for."""
    return importlib.import_module(f".{name}", __name__).write


def group_name(report: FileReport, index: int) -> str:
    """The name of group ``index`` of a report's mesh ("" when it has none)."""
    return report.group_names[index] if 0 <= index < len(report.group_names) else ""


def _rows(report: FileReport, hits: RuleHits, take: np.ndarray) -> list[tuple[int, Finding]]:
    """``(face in file order, finding)`` for the hits at ``take``."""
    rule = RULES[hits.code]
    # Rules without a threshold (Q204, Q205, Q302) measure something else; no limit to report.
    threshold = None if rule.default_threshold is None else hits.threshold
    faces, groups, lines = hits.faces[take], hits.groups[take], hits.lines[take]
    usd = report.prim_face_start is not None
    if usd:  # no lines; faces count within their prim (the file-level face -1 stays -1)
        faces, lines = faces - report.prim_face_start[groups], np.zeros_like(lines)
    return [
        (order, Finding(
            path=report.path,
            line=int(line),
            column=1 if line > 0 else 0,
            code=hits.code,
            name=rule.name,
            face=int(face),
            value=float(value),
            threshold=threshold,
            group=group_name(report, g),
            message=rule.summary,
            prim=group_name(report, g) if usd and order >= 0 else None,
        ))
        for order, face, line, value, g in zip(
            hits.faces[take].tolist(), faces.tolist(), lines.tolist(),
            hits.values[take].tolist(), groups.tolist(),
        )
    ]


def file_findings(report: FileReport, limit: int | None = None) -> tuple[list[Finding], dict[str, int]]:
    """The findings of one file in source order, and how many each rule left out.

    Parameters
    ----------
    limit : int or None
        Keep at most this many findings per rule (the first in file order);
        None keeps all.

    Returns
    -------
    findings : list of Finding, sorted by (line, face in file order, code)
    omitted : dict of rule code to the number of findings beyond ``limit``
    """
    rows: list[tuple[int, Finding]] = []
    omitted: dict[str, int] = {}
    for hits in report.hits:
        order = np.argsort(hits.faces, kind="stable")
        if limit is not None and len(order) > limit:
            omitted[hits.code] = len(order) - limit
            order = order[:limit]
        rows.extend(_rows(report, hits, order))
    rows.sort(key=lambda row: (row[1].line, row[0], row[1].code))
    return [f for _, f in rows], omitted


def rule_counts(reports: list[FileReport]) -> dict[str, int]:
    """Findings per rule code over all reports, in rule-table order."""
    counts = dict.fromkeys(RULES, 0)
    for report in reports:
        for hits in report.hits:
            counts[hits.code] += len(hits)
    return {code: n for code, n in counts.items() if n}


def format_value(value: float) -> str:
    """A measured value for humans: 4 significant digits, no exponent for everyday sizes."""
    return f"{value:.4g}"


def describe(f: Finding) -> str:
    """The message with the measurement: ``... (3.2 vs 0.5 texels)``."""
    measured = format_value(f.value)
    if f.threshold is not None:
        measured += " vs " + with_unit(format_value(f.threshold), RULES[f.code].unit)
    return f"{f.message} ({measured})"


def face_label(f: Finding) -> str:
    """``"face 12"``, ``"/World/Crate face 12"`` in USD; ``""`` for file-level findings (Q205 has face -1)."""
    if f.face < 0:
        return ""
    return f"face {f.face}" if f.prim is None else f"{f.prim} face {f.face}"


def located(f: Finding) -> str:
    """:func:`describe` naming the face, for formats without a text line: ``..., face 12``."""
    return ", ".join(filter(None, [describe(f), face_label(f)]))


def text_line(f: Finding) -> str:
    """The ruff-style line ``path:line:col: CODE name: message (value vs threshold)``;
    ``path:prim:face N: ...`` in USD."""
    where = f"{f.line}:{f.column}" if f.prim is None else f"{f.prim}:face {f.face}"
    return f"{f.path}:{where}: {f.code} {f.name}: {describe(f)}"


def working_relative(path: str) -> str | None:
    """``path`` relative to the working directory with ``/`` separators, None when outside it.

    CI annotations and SARIF locations name files relative to the checkout,
    which is the working directory of a CI step.
    """
    rel = os.path.relpath(os.path.abspath(path), os.getcwd())
    return None if rel.startswith("..") else rel.replace(os.sep, "/")


def value_token(value: float) -> str:
    """A measured value rounded to 6 significant digits: equal for the same quad on every run.

    The per-face measures do not depend on the face's position in the file, so
    this token (with rule, file and group) identifies a finding across face
    reordering and edits elsewhere in the file (baseline, SARIF fingerprints).
    """
    return f"{value:.6g}"

