"""Text output: ``path:line:col: CODE level name: message (value vs threshold unit) [face F]``, one finding a line.

Per file, the errors come first, then the warnings, then info, each the worst
first (:func:`affinity.output.select`), so what fails the gate is what a reader
sees first; at most :data:`TEXT_LIMIT` per file and rule, the worst, unless
verbose. The closing summary counts the findings per level; ``--statistics``
prints count, code, name and level per rule instead of the findings.
"""

from __future__ import annotations

from typing import TextIO

from . import CheckRun, level_counts, select, statistics, text_rows
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
    """Every finding of every checked file, errors first and the worst first, capped per file and rule unless
    verbose."""
    for report in run.reports:
        selection = select(report, None if verbose else TEXT_LIMIT, order="severity")
        for lines in selection.written(text_rows):
            out.write(lines)
        path = printable(report.path)
        out.write("".join(f"{path}: ... and {n} more {code} (use --verbose or --format json for all)\n"
                          for code, n in selection.omitted.items()))


def write_statistics(run: CheckRun, out: TextIO) -> None:
    """One line per rule with findings: count, code, name, level (like ``ruff --statistics``)."""
    for row in statistics(run.reports):
        out.write(f"{row['count']:>8}  {row['code']}  {row['name']}  [{row['level']}]\n")


def write_summary(run: CheckRun, out: TextIO) -> None:
    """One closing line: findings, files checked, unreadable, skipped and baselined."""
    n = run.tally()
    parts = [f"{n['checked']} file{'s' * (n['checked'] != 1)} checked"]
    parts += [f"{n[key]} {key}" for key in ("unreadable", "skipped", "baselined") if n[key]]
    if run.hidden:
        parts.append(f"not shown: {', '.join(f'{k} {level}' for level, k in run.hidden.items())}")
    new = "" if run.baselined is None else "new "
    head = f"Found {n['findings']} {new}finding{'s' * (n['findings'] != 1)}" if n["findings"] else f"No {new}findings"
    levels = ", ".join(f"{k} {level}" for level, k in level_counts(run.reports).items())
    head += f": {levels}" if levels else ""
    out.write(f"{head} ({', '.join(parts)}).\n")
