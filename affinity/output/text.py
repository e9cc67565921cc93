"""Text output: ``path:line:col: CODE name: message (value vs threshold unit) [face F]``, one finding a line.

The closing summary counts the findings per level; ``--statistics`` prints
count, code, name and level per rule instead of the findings.
"""

from __future__ import annotations

from typing import TextIO

from . import CheckRun, file_findings, level_counts, statistics, text_line
from .names import printable

#: Findings shown per file and rule before "... and N more" (design.md, Clarifications).
TEXT_LIMIT = 20


def write(run: CheckRun, out: TextIO, verbose: bool = False, statistics: bool = False, summary: bool = True) -> None:
    """Findings (or per-rule counts with ``statistics``), then the summary line unless ``summary`` is off."""
    if statistics:
        write_statistics(run, out)
    else:
        write_findings(run, out, verbose)
    if summary:
        write_summary(run, out)


def write_findings(run: CheckRun, out: TextIO, verbose: bool = False) -> None:
    """Every finding of every checked file, capped per file and rule unless verbose."""
    for report in run.reports:
        findings, omitted = file_findings(report, None if verbose else TEXT_LIMIT)
        lines = [text_line(f) + "\n" for f in findings]
        lines += [f"{printable(report.path)}: ... and {n} more {code} (use --verbose or --format json for all)\n"
                  for code, n in omitted.items()]
        out.write("".join(lines))


def write_statistics(run: CheckRun, out: TextIO) -> None:
    """One line per rule with findings: count, code, name, level (like ``ruff --statistics``)."""
    for row in statistics(run.reports):
        out.write(f"{row['count']:>8}  {row['code']}  {row['name']}  [{row['level']}]\n")


def write_summary(run: CheckRun, out: TextIO) -> None:
    """One closing line: findings, files checked, unreadable, skipped and baselined."""
    n = run.tally()
    parts = [f"{n['checked']} file{'s' * (n['checked'] != 1)} checked"]
    parts += [f"{n[key]} {key}" for key in ("unreadable", "skipped", "baselined") if n[key]]
    new = "" if run.baselined is None else "new "
    head = f"Found {n['findings']} {new}finding{'s' * (n['findings'] != 1)}" if n["findings"] else f"No {new}findings"
    levels = ", ".join(f"{k} {level}" for level, k in level_counts(run.reports).items())
    head += f": {levels}" if levels else ""
    out.write(f"{head} ({', '.join(parts)}).\n")
