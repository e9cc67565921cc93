"""GitHub Actions workflow annotations: ``::warning file=…,line=…,col=…,title=Q101 uv-disaffine::message``.

Findings of rules at level ``error`` (Q204) become ``::error``, unreadable files
``::error`` with title ``Q901 unreadable``, skipped files ``::notice``. Paths are
relative to the working directory (the checkout in a workflow step). Escaping
follows the Actions runner: in the message ``%``, ``\\r`` and ``\\n``; in property
values also ``:`` and ``,``.
"""

from __future__ import annotations

from typing import TextIO

from ..rules import RULES, UNREADABLE
from . import CheckRun, file_findings, located, working_relative

_DATA_ESCAPES = (("%", "%25"), ("\r", "%0D"), ("\n", "%0A"))
_PROPERTY_ESCAPES = _DATA_ESCAPES + ((":", "%3A"), (",", "%2C"))


def _escape(text: str, escapes) -> str:
    for raw, escaped in escapes:  # "%" first, so escapes are not escaped again
        text = text.replace(raw, escaped)
    return text


def annotation(level: str, message: str, file: str, line: int = 0, col: int = 0, title: str = "") -> str:
    """One workflow command line; ``line``/``col`` 0 are left out (binary PLY, whole file)."""
    props = {"file": file, "line": line or None, "col": col or None, "title": title or None}
    text = ",".join(f"{k}={_escape(str(v), _PROPERTY_ESCAPES)}" for k, v in props.items() if v is not None)
    return f"::{level} {text}::{_escape(message, _DATA_ESCAPES)}"


def write(run: CheckRun, out: TextIO) -> None:
    for report in run.reports:
        path = working_relative(report.path) or report.path
        if report.error is not None:
            title = f"{UNREADABLE.code} {UNREADABLE.name}"
            out.write(annotation("error", report.error, path, report.error_line, title=title) + "\n")
        elif report.skipped is not None:
            out.write(annotation("notice", f"skipped ({report.skipped})", path, title="skipped") + "\n")
        for f in file_findings(report)[0]:
            line = annotation(RULES[f.code].level, located(f), path, f.line, f.column,
                              title=f"{f.code} {f.name}")
            out.write(line + "\n")
