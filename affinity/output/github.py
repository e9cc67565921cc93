"""GitHub Actions workflow annotations: ``::warning file=…,line=…,col=…,title=Q101 uv-disaffine::message``.

At most one annotation per file and rule (GitHub shows only a handful per step
anyway): it stands on the worst finding's line and gives the count, the worst
value and the first few faces with their lines. Its level is the worst finding's
(``error`` -> ``::error``, ``warning`` -> ``::warning``, ``info`` -> ``::notice``).
Without ``--max-findings`` a run writes at most 5,000 of them, each ranked by its
worst finding: the failing level first, a fair share per file
(:func:`affinity.output.cap.cap_findings`); a ``::warning`` and one line on
stderr say per level what was cut;
unreadable files are ``::error`` with title ``Q901 unreadable``, skipped files
``::notice``. ``--statistics`` adds one ``::notice`` per rule with its count. Paths are
relative to the working directory (the checkout in a workflow step). Escaping
follows the Actions runner: in the message ``%``, ``\\r`` and ``\\n``; in property
values also ``:`` and ``,``.
"""

from __future__ import annotations

import re
import sys
from typing import TextIO

import numpy as np

from ..rules import UNREADABLE
from . import (
    CheckRun,
    Finding,
    badness,
    describe,
    face_label,
    first_findings,
    statistics,
    working_relative,
    worst_findings,
    worst_first,
)
from .cap import cap_findings

#: Faces listed in a rule's annotation.
FIRST_FACES = 5
_COMMANDS = {"error": "error", "warning": "warning", "info": "notice"}

_DATA_ESCAPES = (("%", "%25"), ("\r", "%0D"), ("\n", "%0A"))
_PROPERTY_ESCAPES = _DATA_ESCAPES + ((":", "%3A"), (",", "%2C"))


#: The other C0 controls and DEL (ESC would reach a terminal that shows the log raw): percent-escaped too.
_CONTROLS = re.compile("[\\x00-\\x08\\x0b\\x0c\\x0e-\\x1f\\x7f]")


def _escape(text: str, escapes) -> str:
    for raw, escaped in escapes:  # "%" first, so escapes are not escaped again
        text = text.replace(raw, escaped)
    return _CONTROLS.sub(lambda control: f"%{ord(control[0]):02X}", text)


def annotation(level: str, message: str, file: str, line: int = 0, col: int = 0, title: str = "") -> str:
    """One workflow command line; ``line``/``col`` 0 are left out (binary PLY, whole file)."""
    props = {"file": file, "line": line or None, "col": col or None, "title": title or None}
    text = ",".join(f"{k}={_escape(str(v), _PROPERTY_ESCAPES)}" for k, v in props.items() if v is not None)
    return f"::{level} {text}::{_escape(message, _DATA_ESCAPES)}"


def _kept(run: CheckRun) -> tuple[dict[int, Finding], str | None]:
    """id of a rule's hits -> its worst finding, for the annotations the run cap keeps (each stands for its
    worst finding: :func:`affinity.output.cap.cap_findings`); and the truncation notice."""
    worst = [[(hits, worst_first(hits)[0]) for hits in report.hits] for report in run.reports]
    if run.max_findings is None:
        ranked = [(np.array([hits.level_ranks()[w] for hits, w in rules], dtype=np.int8),
                   np.array([badness(hits)[w] for hits, w in rules], dtype=float)) for rules in worst]
        capped = cap_findings(ranked, run.fail_on, run.run_cap)
        kept, notice = capped.kept, capped.note("GitHub annotations (one per file and rule)")
    else:
        kept, notice = [range(len(rules)) for rules in worst], None
    return {id(rules[i][0]): worst_findings(report, rules[i][0], 1)[0]
            for report, rules, rows in zip(run.reports, worst, kept) for i in list(rows)}, notice


def write(run: CheckRun, out: TextIO) -> None:
    kept, truncated = _kept(run)
    for report in run.reports:
        path = working_relative(report.path) or report.path
        if report.error is not None:
            title = f"{UNREADABLE.code} {UNREADABLE.name}"
            out.write(annotation("error", report.error, path, report.error_line, title=title) + "\n")
        elif report.skipped is not None:
            out.write(annotation("notice", f"skipped ({report.skipped})", path, title="skipped") + "\n")
        for hits in report.hits:
            if id(hits) in kept:
                out.write(_rule_annotation(report, hits, kept[id(hits)], path) + "\n")
    if truncated is not None:
        out.write(annotation("warning", truncated, ".", title="truncated") + "\n")
        sys.stderr.write(f"affinity: {truncated}\n")
    if run.statistics:
        for row in statistics(run.reports):
            out.write(annotation("notice", f"{row['count']} findings of {row['code']} {row['name']} ({row['level']})",
                                 ".", title="statistics") + "\n")


def _rule_annotation(report, hits, worst, path: str) -> str:
    """The one annotation of a rule in a file, standing on its ``worst`` finding."""
    first = first_findings(report, hits, FIRST_FACES)

    def where(f) -> str:
        return face_label(f) + (f" (line {f.line})" if f.line > 0 else "")

    located = describe(worst) + (f", {where(worst)}" if face_label(worst) else "")
    if len(hits) == 1:
        message = located
    else:
        listed = ", ".join(where(f) for f in first if face_label(f))
        more = ", ..." if len(hits) > len(first) else ""
        message = f"{len(hits)} findings, the worst: {located}" + (f"; first: {listed}{more}" if listed else "")
    return annotation(_COMMANDS[worst.level], message, path, worst.line, worst.column,
                      title=f"{worst.code} {worst.name}")
