"""Output formats for ``affinity check``. Each module formats a list of FileReport."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..findings import FileReport, RuleHits
from ..rules import RULES


@dataclass(frozen=True)
class Finding:
    """One finding, as every structured format carries it (design.md, "Rule codes")."""

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


def _rows(report: FileReport, hits: RuleHits, take: np.ndarray) -> list[Finding]:
    rule = RULES[hits.code]
    groups = report.group_names
    return [
        Finding(
            path=report.path,
            line=int(line),
            column=1 if line > 0 else 0,
            code=hits.code,
            name=rule.name,
            face=int(face),
            value=float(value),
            threshold=hits.threshold,
            group=groups[g] if 0 <= g < len(groups) else "",
            message=rule.summary,
        )
        for face, line, value, g in zip(
            hits.faces[take].tolist(), hits.lines[take].tolist(),
            hits.values[take].tolist(), hits.groups[take].tolist(),
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
    findings : list of Finding, sorted by (line, face, code)
    omitted : dict of rule code to the number of findings beyond ``limit``
    """
    rows: list[Finding] = []
    omitted: dict[str, int] = {}
    for hits in report.hits:
        order = np.argsort(hits.faces, kind="stable")
        if limit is not None and len(order) > limit:
            omitted[hits.code] = len(order) - limit
            order = order[:limit]
        rows.extend(_rows(report, hits, order))
    rows.sort(key=lambda f: (f.line, f.face, f.code))
    return rows, omitted


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
