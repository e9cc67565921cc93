"""Text output: ``path:line:col: CODE name: message (value vs threshold)``, one finding a line."""

from __future__ import annotations

from typing import TextIO

from ..findings import FileReport
from ..rules import RULES
from . import file_findings, format_value, rule_counts

#: Findings shown per file and rule before "... and N more" (design.md, Clarifications).
TEXT_LIMIT = 20


def write(reports: list[FileReport], out: TextIO, verbose: bool = False) -> None:
    """Write every finding of every checked file, capped per file and rule unless verbose."""
    for report in reports:
        findings, omitted = file_findings(report, None if verbose else TEXT_LIMIT)
        for f in findings:
            unit = RULES[f.code].unit
            measured = format_value(f.value)
            if f.threshold is not None:
                measured += f" vs {format_value(f.threshold)}"
                if unit:
                    measured += f" {unit}"
            out.write(f"{f.path}:{f.line}:{f.column}: {f.code} {f.name}: {f.message} ({measured})\n")
        for code, n in omitted.items():
            out.write(f"{report.path}: ... and {n} more {code} (use --verbose or --format json for all)\n")


def write_statistics(reports: list[FileReport], out: TextIO) -> None:
    """One line per rule with findings: count, code, name (like ``ruff --statistics``)."""
    for code, n in rule_counts(reports).items():
        out.write(f"{n:>8}  {code}  {RULES[code].name}\n")


def write_summary(reports: list[FileReport], out: TextIO) -> None:
    """One closing line: findings, files checked, unreadable and skipped."""
    findings = sum(r.n_findings for r in reports)
    unreadable = sum(r.error is not None for r in reports)
    skipped = sum(r.skipped is not None for r in reports)
    checked = len(reports) - unreadable - skipped
    parts = [f"{checked} file{'s' * (checked != 1)} checked"]
    if unreadable:
        parts.append(f"{unreadable} unreadable")
    if skipped:
        parts.append(f"{skipped} skipped")
    head = f"Found {findings} finding{'s' * (findings != 1)}" if findings else "No findings"
    out.write(f"{head} ({', '.join(parts)}).\n")
