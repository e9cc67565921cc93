"""JUnit XML, for CI systems that show test reports (GitLab, Jenkins, Azure).

One ``<testsuite>`` per file, one ``<testcase>`` per finding with a
``<failure>`` (type = rule code, body = the text line, properties face, value,
threshold, line, column, code, name, group, and prim in USD); a clean file gets
one passing testcase, an unreadable file one testcase with an ``<error>`` (type
Q901), a skipped file one with ``<skipped>``.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from typing import TextIO

from ..findings import FileReport
from ..rules import UNREADABLE
from . import CheckRun, Finding, describe, face_label, file_findings, statistics, text_line

# Characters XML 1.0 cannot carry at all (control characters, lone surrogates from undecodable file names).
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _make_xml_safe(root: ET.Element) -> None:
    """Replace characters XML cannot represent with U+FFFD in every attribute and text."""
    for element in root.iter():
        element.attrib.update({k: _NOT_XML.sub("\ufffd", v) for k, v in element.attrib.items()})
        if element.text:
            element.text = _NOT_XML.sub("\ufffd", element.text)


def _finding_case(suite: ET.Element, f: Finding) -> None:
    name = " ".join(filter(None, [f.code, f.name, face_label(f)]))
    case = ET.SubElement(suite, "testcase", classname=f.path, name=name, file=f.path, line=str(f.line))
    props = ET.SubElement(case, "properties")
    keys = (("face", "value", "threshold", "unit", "level", "line", "column", "code", "name", "group")
            + ("prim",) * (f.prim is not None))
    for key in keys:
        ET.SubElement(props, "property", name=key, value=str(getattr(f, key)))
    failure = ET.SubElement(case, "failure", type=f.code, message=describe(f))
    failure.text = text_line(f)


def _suite(report: FileReport) -> ET.Element:
    findings = file_findings(report)[0]
    suite = ET.Element("testsuite", name=report.path)
    if report.error is not None:
        case = ET.SubElement(suite, "testcase", classname=report.path, name=f"{UNREADABLE.code} {UNREADABLE.name}")
        error = ET.SubElement(case, "error", type=UNREADABLE.code, message=report.error)
        error.text = f"{report.path}:{report.error_line}: {UNREADABLE.code} {UNREADABLE.name}: {report.error}"
    elif report.skipped is not None:
        case = ET.SubElement(suite, "testcase", classname=report.path, name="affinity check")
        ET.SubElement(case, "skipped", message=report.skipped)
    elif not findings:
        ET.SubElement(suite, "testcase", classname=report.path, name="affinity check")
    for f in findings:
        _finding_case(suite, f)
    suite.set("tests", str(len(suite)))
    suite.set("failures", str(len(findings)))
    suite.set("errors", str(int(report.error is not None)))
    suite.set("skipped", str(int(report.skipped is not None)))
    return suite


def write(run: CheckRun, out: TextIO) -> None:
    root = ET.Element("testsuites", name="affinity check")
    if run.statistics:  # per-rule counts as properties of the run
        props = ET.SubElement(root, "properties")
        for row in statistics(run.reports):
            ET.SubElement(props, "property", name=f"{row['code']} {row['name']} ({row['level']})",
                          value=str(row["count"]))
    root.extend(_suite(report) for report in run.reports)
    for key in ("tests", "failures", "errors", "skipped"):
        root.set(key, str(sum(int(suite.get(key)) for suite in root if suite.tag == "testsuite")))
    _make_xml_safe(root)
    ET.indent(root)
    out.write('<?xml version="1.0" encoding="utf-8"?>\n')
    out.write(ET.tostring(root, encoding="unicode"))
    out.write("\n")
