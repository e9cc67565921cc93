"""JUnit XML, for CI systems that show test reports (GitLab, Jenkins, Azure).

One ``<testsuite>`` per file, one ``<testcase>`` per finding, named after the
rule and the face (and the prim in USD), with the file and line as attributes;
its text line (level, value, threshold and unit included) is its body. A
finding at or above ``--fail-on`` is a ``<failure>`` (type = rule code,
message = the rule's code, name and summary, body = the text line with the
measurement); one below it is reported
without failing, its text line in the testcase's ``<system-out>``, so the
report's failures are what fails the run. A clean file gets one passing
testcase, an unreadable file one testcase with an ``<error>`` (type Q901), a
skipped file one with ``<skipped>``. Without ``--level``, ``affinity check`` leaves the info
findings out of JUnit (:data:`affinity.commands.check.JUNIT_LEVEL`): they never fail a gate.

The XML is written as text, file by file and a block of findings at a time:
time and memory grow with the findings, with small constants. Characters XML
1.0 cannot carry (control characters, lone surrogates from undecodable file
names) become U+FFFD.
"""

from __future__ import annotations

import re
from typing import TextIO

import numpy as np

from ..findings import FileReport
from ..rules import LEVELS, RULES, UNREADABLE
from ..rules.wording import unreadable_line
from . import CheckRun, Columns, Selection, face_line_pieces, rows, statistics, text_lines

# Characters XML 1.0 cannot carry at all (control characters, lone surrogates from undecodable file names).
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def xml_text(text: str) -> str:
    """``text`` as XML character data: ``&``, ``<``, ``>`` escaped, what XML cannot carry replaced."""
    return _NOT_XML.sub("\ufffd", text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;"))


def xml_attribute(text: str) -> str:
    """``text`` as a double-quoted attribute value (quotes, tabs and line breaks kept as references)."""
    return (xml_text(text).replace('"', "&quot;").replace("\t", "&#9;").replace("\n", "&#10;")
            .replace("\r", "&#13;"))


def _attributes(**values) -> str:
    return "".join(f' {name}="{xml_attribute(str(value))}"' for name, value in values.items())


def _finding_cases(fail_on: str):
    """The ``<testcase>`` text of each finding of a :class:`Columns` (a grid of rows, :mod:`.rows`, for
    findings on faces): failing at ``fail_on`` and above."""
    failing = set(LEVELS[: LEVELS.index(fail_on) + 1])

    def cases(c: Columns) -> np.ndarray | list[str]:
        path = xml_attribute(c.path)
        rule = f"{xml_attribute(c.code)} {xml_attribute(c.name)}"
        failure = f'<failure type="{xml_attribute(c.code)}" message="{rule}: {xml_attribute(RULES[c.code].summary)}">'
        if c.on_faces:  # measured faces of a mesh file: one shape for every case, laid out a column at a time
            fails = c.level_ranks <= LEVELS.index(fail_on)
            return rows.grid([f'<testcase classname="{path}" name="{rule} face '.encode(), c.face_digits,
                              f'" file="{path}" line="'.encode(), c.line_digits,
                              rows.choice(fails, ['"><system-out>', f'">{failure}']),
                              *face_line_pieces(c, xml_text),
                              rows.choice(fails, ["</system-out></testcase>\n", "</failure></testcase>\n"])], len(c))
        lines = list(map(xml_text, text_lines(c)))  # a bound reads "<=", texts may hold "&"
        names = [rule if face < 0 else f"{rule} face {face}" if prim is None
                 else f"{rule} {xml_attribute(prim)} face {face}" for face, prim in zip(c.face, c.prim)]
        return [f'<testcase classname="{path}" name="{name}" file="{path}" line="{line}">'
                + (f"{failure}{t}</failure></testcase>\n" if level in failing
                   else f"<system-out>{t}</system-out></testcase>\n")
                for name, line, level, t in zip(names, c.line, c.level, lines)]

    return cases


def _counts(run: CheckRun, report: FileReport, selection: Selection) -> dict[str, int]:
    """The ``tests``, ``failures``, ``errors``, ``skipped`` of a file's testsuite."""
    failures = int((selection.level_ranks() <= LEVELS.index(run.fail_on)).sum())
    return {"tests": max(len(selection), 1), "failures": failures, "errors": int(report.error is not None),
            "skipped": int(report.skipped is not None)}


def _suite(run: CheckRun, selection: Selection, counts: dict[str, int], out: TextIO) -> None:
    report = selection.report
    out.write(f"  <testsuite{_attributes(name=report.path, **counts)}>\n")
    path = xml_attribute(report.path)
    if report.error is not None:
        text = unreadable_line(report.path, report.error, report.error_line)
        out.write(f'    <testcase classname="{path}" name="{UNREADABLE.code} {UNREADABLE.name}">'
                  f'<error{_attributes(type=UNREADABLE.code, message=report.error)}>{xml_text(text)}</error>'
                  "</testcase>\n")
    elif report.skipped is not None:
        out.write(f'    <testcase classname="{path}" name="affinity check">'
                  f"<skipped{_attributes(message=report.skipped)}/></testcase>\n")
    elif not report.hits:
        out.write(f'    <testcase classname="{path}" name="affinity check"/>\n')
    for block in selection.written(_finding_cases(run.fail_on)):
        out.write(block)
    out.write("  </testsuite>\n")


def write(run: CheckRun, out: TextIO) -> None:
    selections = [run.kept(report) for report in run.reports]
    counts = [_counts(run, s.report, s) for s in selections]
    totals = {key: sum(c[key] for c in counts) for key in ("tests", "failures", "errors", "skipped")}
    out.write('<?xml version="1.0" encoding="utf-8"?>\n')
    out.write(f'<testsuites{_attributes(name="affinity check", **totals)}>\n')
    if run.statistics:  # per-rule counts as properties of the run
        named = [("{code} {name} ({level})".format(**row), row["count"]) for row in statistics(run.reports)]
        out.write("  <properties>\n" + "".join(f"    <property{_attributes(name=name, value=count)}/>\n"
                                                for name, count in named) + "  </properties>\n")
    for selection, suite_counts in zip(selections, counts):
        _suite(run, selection, suite_counts, out)
    out.write("</testsuites>\n")
