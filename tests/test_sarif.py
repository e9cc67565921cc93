"""SARIF output: validates against the official SARIF 2.1.0 schema (tests/data/sarif, no network)."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
from helpers.cli import run
from helpers.quads import SQUARE, UNIT_UV, hits, quad_obj, sample_run, trapezoid
from helpers.sarif import assert_valid

from affinity.findings import FileReport
from affinity.output import CheckRun, sarif
from affinity.rules import RULES, rule_page
from affinity.settings import Settings


def sarif_log(run_: CheckRun) -> dict:
    out = io.StringIO()
    sarif.write(run_, out)
    return json.loads(out.getvalue())




def test_schema_rejects_a_broken_log():
    """The validator is really checking: a result without a message is not SARIF."""
    log = sarif_log(sample_run())
    del log["runs"][0]["results"][0]["message"]
    with pytest.raises(AssertionError):
        assert_valid(log)


def test_sample_log_validates_with_rules_results_and_notifications(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    log = sarif_log(sample_run())
    assert_valid(log)
    (sarif_run,) = log["runs"]
    driver = sarif_run["tool"]["driver"]
    assert [r["id"] for r in driver["rules"]] == list(RULES)
    q101 = driver["rules"][0]
    assert q101["name"] == "uv-disaffine" and q101["help"]["text"] == rule_page(RULES["Q101"])
    assert "### Why it matters" in q101["help"]["markdown"]

    results = sarif_run["results"]
    assert [(r["ruleId"], r["level"]) for r in results] == [("Q101", "warning"), ("Q204", "error"), ("Q101", "warning")]
    for r in results:
        assert driver["rules"][r["ruleIndex"]]["id"] == r["ruleId"]
    location = results[2]["locations"][0]["physicalLocation"]
    assert location == {"artifactLocation": {"uri": "a%2C%20b%3Ac.obj", "uriBaseId": "%SRCROOT%"},
                        "region": {"startLine": 12, "startColumn": 1}}
    assert results[2]["properties"] == {"name": "uv-disaffine", "face": 2, "value": 256.0, "threshold": 0.5,
                                        "unit": "texels", "level": "warning", "group": "body"}
    assert sarif_run["originalUriBaseIds"]["%SRCROOT%"]["uri"] == tmp_path.as_uri() + "/"

    (invocation,) = sarif_run["invocations"]
    assert invocation["executionSuccessful"] is False
    unreadable, skipped = invocation["toolExecutionNotifications"]
    assert unreadable["level"] == "error" and unreadable["descriptor"]["id"] == "Q901"
    assert unreadable["locations"][0]["physicalLocation"]["region"] == {"startLine": 4}
    assert skipped["level"] == "note"


def test_binary_ply_finding_has_no_region_and_still_validates(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    log = sarif_log(CheckRun([FileReport("scan.ply", hits=[hits("Q202", [5], [0], [0.2], 0.01)])], Settings()))
    assert_valid(log)
    (result,) = log["runs"][0]["results"]
    assert "region" not in result["locations"][0]["physicalLocation"]
    assert result["locations"][0]["logicalLocations"][0]["name"] == "face 5"
    assert log["runs"][0]["invocations"][0]["executionSuccessful"] is True


def test_file_level_finding_has_no_logical_location(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    log = sarif_log(CheckRun([FileReport("points.obj", hits=[hits("Q205", [-1], [1], [2.0], 0.0)])], Settings()))
    assert_valid(log)
    (result,) = log["runs"][0]["results"]
    assert "logicalLocations" not in result["locations"][0]
    assert result["message"]["text"] == "the mesh has vertices but no faces (2 vertices)"


def test_file_outside_the_working_directory_gets_an_absolute_uri(tmp_path, monkeypatch):
    (tmp_path / "here").mkdir()
    monkeypatch.chdir(tmp_path / "here")
    outside = str(tmp_path / "elsewhere.obj")
    log = sarif_log(CheckRun([FileReport(outside, hits=[hits("Q101", [0], [3], [9.0])])], Settings()))
    assert_valid(log)
    location = log["runs"][0]["results"][0]["locations"][0]["physicalLocation"]["artifactLocation"]
    assert location == {"uri": Path(outside).as_uri()}


def fingerprints(report: FileReport) -> list[str]:
    return [r["partialFingerprints"]["quadAffinity/v1"]
            for r in sarif_log(CheckRun([report], Settings()))["runs"][0]["results"]]


def test_fingerprints_survive_face_reordering_but_not_a_changed_quad():
    before = FileReport("m.obj", group_names=["g"], hits=[hits("Q101", [0, 1, 2], [5, 6, 7], [3.0, 3.0, 8.0])])
    reordered = FileReport("m.obj", group_names=["g"], hits=[hits("Q101", [4, 9, 11], [9, 14, 16], [8.0, 3.0, 3.0])])
    changed = FileReport("m.obj", group_names=["g"], hits=[hits("Q101", [0, 1, 2], [5, 6, 7], [3.0, 3.0, 8.5])])
    assert len(set(fingerprints(before))) == 3  # equal values still get distinct fingerprints
    assert sorted(fingerprints(before)) == sorted(fingerprints(reordered))
    assert len(set(fingerprints(before)) & set(fingerprints(changed))) == 2


def test_sarif_end_to_end_validates(tmp_path):
    (tmp_path / "bad.obj").write_text(quad_obj([(trapezoid(), UNIT_UV)], header="# trapezoid"))
    (tmp_path / "good.obj").write_text(quad_obj([(SQUARE, UNIT_UV)]))
    (tmp_path / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n")
    result = run("check", "--format", "sarif", ".", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    log = json.loads(result.stdout)
    assert_valid(log)
    (sarif_run,) = log["runs"]
    (finding,) = sarif_run["results"]
    assert finding["ruleId"] == "Q101"
    assert finding["locations"][0]["physicalLocation"] == {
        "artifactLocation": {"uri": "bad.obj", "uriBaseId": "%SRCROOT%"},
        "region": {"startLine": 10, "startColumn": 1},
    }
    (note,) = sarif_run["invocations"][0]["toolExecutionNotifications"]
    assert note["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == "broken.obj"
    again = json.loads(run("check", "--format", "sarif", ".", cwd=tmp_path).stdout)
    assert again["runs"][0]["results"][0]["partialFingerprints"] == finding["partialFingerprints"]
