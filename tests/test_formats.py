"""Output formats (text, json, github, junit) on reports with known findings.

Unit tests build FileReport/RuleHits by hand; end-to-end tests run ``affinity
check`` on a trapezoid carrying a unit-square uv (Q101: the split moves the
texture by up to 175.7 texels at 1024, (1 - r) / (1 + sqrt r)^2 of its width for
the side ratio r = 1/2) next to a square with affine uv (clean).
"""

from __future__ import annotations

import io
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from helpers.cli import run
from helpers.quads import SQUARE, UNIT_UV, hits, quad_obj, sample_run, trapezoid

from affinity.findings import FileReport
from affinity.output import CheckRun, github, junit, text
from affinity.output import json as json_output
from affinity.settings import Settings


def render(module, run_: CheckRun) -> str:
    out = io.StringIO()
    module.write(run_, out)
    return out.getvalue()


def test_text_lines_and_summary():
    """Each line carries its level after the code; the error comes first, then the warnings, the worst first."""
    out = io.StringIO()
    text.write(sample_run(), out)
    assert out.getvalue().splitlines() == [
        "a, b:c.obj:11:1: Q204 error bowtie-quad: the quad crosses itself (0.3 folded fraction) [face 1]",
        "a, b:c.obj:12:1: Q101 warning uv-disaffine: texture coordinates are not an affine image of the positions "
        "(256 vs 0.5 texels) [face 2]",
        "a, b:c.obj:10:1: Q101 warning uv-disaffine: texture coordinates are not an affine image of the positions "
        "(3.5 vs 0.5 texels) [face 0]",
        "Found 3 findings: 1 error, 2 warning (2 files checked, 1 unreadable, 1 skipped).",
    ]


def test_text_summary_counts_baselined_findings():
    run_ = sample_run()
    run_.baselined = {"a, b:c.obj": 4}
    assert render(text, run_).splitlines()[-1] == (
        "Found 3 new findings: 1 error, 2 warning (2 files checked, 1 unreadable, 1 skipped, 4 baselined)."
    )


def test_github_annotations_escape_and_levels():
    """One annotation per file and rule, on the worst finding's line, with the count and the first faces."""
    lines = render(github, sample_run()).splitlines()
    assert lines == [
        "::warning file=a%2C b%3Ac.obj,line=12,col=1,title=Q101 uv-disaffine::2 findings, the worst: texture "
        "coordinates are not an affine image of the positions (256 vs 0.5 texels), face 2 (line 12); "
        "first: face 0 (line 10), face 2 (line 12)",
        "::error file=a%2C b%3Ac.obj,line=11,col=1,title=Q204 bowtie-quad::the quad crosses itself "
        "(0.3 folded fraction), face 1 (line 11)",
        "::error file=broken.obj,line=4,title=Q901 unreadable::face index 9 out of range%0D%0A(1 based)",
        "::notice file=big.obj,title=skipped::skipped (lfs-pointer)",
    ]


def test_github_annotation_level_is_the_findings_level():
    info = hits("Q101", [0], [10], [3.5])
    info.level = "info"
    (line,) = render(github, CheckRun([FileReport("a.obj", hits=[info])], Settings())).splitlines()
    assert line.startswith("::notice file=a.obj,line=10,col=1,title=Q101 uv-disaffine::")


def test_github_leaves_out_line_zero_and_escapes_percent():
    run_ = CheckRun([FileReport("50%.ply", hits=[hits("Q101", [7], [0], [2.0])])], Settings())
    (line,) = render(github, run_).splitlines()
    assert line.startswith("::warning file=50%25.ply,title=Q101 uv-disaffine::")


def test_file_level_finding_names_no_face():
    run_ = CheckRun([FileReport("points.obj", hits=[hits("Q205", [-1], [1], [2.0], 0.0)])], Settings())
    assert render(github, run_).splitlines() == [
        "::warning file=points.obj,line=1,col=1,title=Q205 no-faces::the mesh has vertices but no faces (2 vertices)"]
    assert ET.fromstring(render(junit, run_)).find("testsuite/testcase").get("name") == "Q205 no-faces"


def test_junit_is_valid_xml_with_failures_errors_and_skips():
    """Only the findings at or above --fail-on (default error) fail; the warnings are reported in system-out."""
    root = ET.fromstring(render(junit, sample_run()))
    assert root.tag == "testsuites"
    assert {k: root.get(k) for k in ("tests", "failures", "errors", "skipped")} == {
        "tests": "6", "failures": "1", "errors": "1", "skipped": "1"}
    suites = {s.get("name"): s for s in root.findall("testsuite")}
    assert list(suites) == ["a, b:c.obj", "clean.obj", "broken.obj", "big.obj"]
    assert suites["a, b:c.obj"].get("failures") == "1"
    flagged = suites["a, b:c.obj"].findall("testcase")
    assert [c.find("failure").get("type") if c.find("failure") is not None else None for c in flagged] == [
        None, "Q204", None]
    assert flagged[2].find("system-out").text.startswith("a, b:c.obj:12:1: Q101 warning uv-disaffine:")
    warning_gate = sample_run()
    warning_gate.fail_on = "warning"
    assert ET.fromstring(render(junit, warning_gate)).get("failures") == "3"
    assert flagged[2].get("name") == "Q101 uv-disaffine face 2" and flagged[2].get("line") == "12"
    (clean,) = suites["clean.obj"].findall("testcase")
    assert list(clean) == []  # a passing testcase
    assert suites["broken.obj"].find("testcase/error").get("type") == "Q901"
    assert suites["big.obj"].find("testcase/skipped") is not None


def test_junit_survives_characters_xml_cannot_carry():
    run_ = CheckRun([FileReport("junk.obj", error="binary junk \x00\x07 at byte 3")], Settings())
    error = ET.fromstring(render(junit, run_)).find("testsuite/testcase/error")
    assert error.get("message") == "binary junk \ufffd\ufffd at byte 3"


def test_json_summary_and_thresholdless_rules():
    doc = json.loads(render(json_output, sample_run()))
    assert doc["summary"] == {"files": 4, "checked": 2, "unreadable": 1, "skipped": 1, "findings": 3,
                              "baselined": 0, "by_rule": {"Q101": 2, "Q204": 1},
                              "by_level": {"error": 1, "warning": 2}}
    bowtie = next(f for f in doc["findings"] if f["code"] == "Q204")
    assert bowtie["threshold"] is None and bowtie["group"] == "body"


# End to end: the CLI on real files.

@pytest.fixture
def meshes(tmp_path: Path) -> Path:
    (tmp_path / "bad.obj").write_text(quad_obj([(trapezoid(), UNIT_UV)], header="# trapezoid"))
    (tmp_path / "good.obj").write_text(quad_obj([(SQUARE, UNIT_UV)]))
    return tmp_path


def test_github_format_end_to_end(meshes):
    result = run("check", "--format", "github", "bad.obj", "good.obj", cwd=meshes)
    assert result.returncode == 1, result.stderr
    assert result.stdout.splitlines() == [
        "::error file=bad.obj,line=10,col=1,title=Q101 uv-disaffine::texture coordinates are not an affine "
        "image of the positions: no texture found, texels of an assumed 1024x1024 texture (give the size with "
        "--texture-size or the texture-size setting) (175.7 vs 0.5 texels), face 0 (line 10)",
    ]


def test_junit_format_end_to_end(meshes):
    result = run("check", "--format", "junit", "bad.obj", "good.obj", cwd=meshes)
    assert result.returncode == 1, result.stderr
    root = ET.fromstring(result.stdout)
    assert (root.get("tests"), root.get("failures"), root.get("errors")) == ("2", "1", "0")
    failure = root.find("testsuite[@name='bad.obj']/testcase/failure")
    assert failure.get("type") == "Q101" and failure.text.startswith("bad.obj:10:1: Q101 error uv-disaffine:")
    assert root.find("testsuite[@name='good.obj']/testcase/failure") is None


def test_json_format_end_to_end(meshes):
    result = run("check", "--format", "json", "bad.obj", "good.obj", cwd=meshes)
    assert result.returncode == 1, result.stderr
    doc = json.loads(result.stdout)
    (finding,) = doc["findings"]
    assert {k: finding[k] for k in ("path", "line", "column", "code", "name", "face")} == {
        "path": "bad.obj", "line": 10, "column": 1, "code": "Q101", "name": "uv-disaffine", "face": 0}
    assert finding["value"] == pytest.approx(1024 * 0.5 / (1 + 0.5**0.5) ** 2, rel=1e-5) and finding["threshold"] == 0.5
    assert [f["findings"] for f in doc["files"]] == [1, 0]


def test_unreadable_file_in_structured_formats_exits_2(meshes):
    (meshes / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n")
    result = run("check", "--format", "github", "broken.obj", "bad.obj", cwd=meshes)
    assert result.returncode == 2
    assert result.stdout.startswith("::error file=broken.obj,line=4,title=Q901 unreadable::")
    assert result.stderr.startswith("broken.obj:4: Q901 unreadable:")


def test_junit_of_a_mesh_with_warnings_only_has_no_failures(shared_meshes):
    """The vase's 288 findings are warnings (under 2 texels): exit 0, and JUnit agrees; --fail-on warning fails both."""
    vase = str(shared_meshes / "gen_vase_revolution.obj")
    result = run("check", "--format", "junit", vase)
    assert result.returncode == 0, result.stderr
    root = ET.fromstring(result.stdout)
    assert (root.get("tests"), root.get("failures")) == ("288", "0")
    assert all(case.find("system-out").text.split(": ", 2)[1].startswith("Q101 warning ")
               for case in root.iter("testcase"))
    gated = run("check", "--format", "junit", "--fail-on", "warning", vase)
    assert gated.returncode == 1 and ET.fromstring(gated.stdout).get("failures") == "288"
