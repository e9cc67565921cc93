"""Baselines: known findings per (file, group, rule) with counts; only new findings fail."""

from __future__ import annotations

import json
from pathlib import Path

from helpers.cli import run
from helpers.quads import SQUARE, UNIT_UV, hits, quad_obj, trapezoid

from affinity.findings import FileReport
from affinity.pipeline import baseline

# Three trapezoids of different shapes (different Q101 values) in two groups, and a clean square.
QUADS = [(trapezoid(1.0, 0), UNIT_UV), (SQUARE, UNIT_UV), (trapezoid(0.5, 3), UNIT_UV), (trapezoid(1.5, 6), UNIT_UV)]
GROUPS = ["body", "body", "body", "lid"]


def report(faces, values, groups, path="m.obj") -> FileReport:
    return FileReport(path, group_names=["body", "lid"], hits=[hits("Q101", faces, faces, values, groups=groups)])


def roundtrip(reports, tmp_path: Path) -> baseline.Baseline:
    file = tmp_path / "baseline.json"
    baseline.write(baseline.record(reports, str(file)), str(file))
    return baseline.read(str(file))


def test_record_counts_per_file_group_and_rule(tmp_path):
    (tmp_path / "assets").mkdir()
    known = roundtrip([report([0, 2, 3], [5.0, 9.0, 7.0], [0, 0, 1], path=str(tmp_path / "assets/m.obj"))], tmp_path)
    assert known.counts == {("assets/m.obj", "body", "Q101"): 2, ("assets/m.obj", "lid", "Q101"): 1}
    doc = json.loads((tmp_path / "baseline.json").read_text())
    assert "faces" not in json.dumps(doc) and doc["entries"][0]["values"] == ["5", "9"]


def test_reordered_faces_are_still_known(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    known = roundtrip([report([0, 2, 3], [5.0, 9.0, 7.0], [0, 0, 1])], tmp_path)
    reports, hidden = baseline.apply([report([7, 1, 4], [7.0, 9.0, 5.0], [1, 0, 0])], known)
    assert reports[0].n_findings == 0 and hidden == {"m.obj": 3}


def test_one_more_finding_is_new_and_it_is_the_unknown_one(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    known = roundtrip([report([0, 2], [5.0, 9.0], [0, 0])], tmp_path)
    reports, hidden = baseline.apply([report([0, 1, 2], [5.0, 6.5, 9.0], [0, 0, 0])], known)
    (new,) = reports[0].hits
    assert new.faces.tolist() == [1] and new.values.tolist() == [6.5] and hidden == {"m.obj": 2}


def test_a_finding_in_another_group_or_file_is_new(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    known = roundtrip([report([0], [5.0], [0])], tmp_path)
    reports, _ = baseline.apply([report([0], [5.0], [1]), report([0], [5.0], [0], path="other.obj")], known)
    assert [r.n_findings for r in reports] == [1, 1]


def test_counts_decide_even_when_values_changed(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    known = roundtrip([report([0, 1], [5.0, 9.0], [0, 0])], tmp_path)
    reports, _ = baseline.apply([report([0, 1], [5.5, 9.5], [0, 0])], known)
    assert reports[0].n_findings == 0


def test_paths_are_relative_to_the_baseline_folder(tmp_path, monkeypatch):
    (tmp_path / "ci").mkdir()
    monkeypatch.chdir(tmp_path / "ci")
    known = roundtrip([report([0], [5.0], [0], path="../m.obj")], tmp_path / "ci")
    assert list(known.counts) == [("../m.obj", "body", "Q101")]
    monkeypatch.chdir(tmp_path)
    reports, _ = baseline.apply([report([0], [5.0], [0], path="m.obj")], known)
    assert reports[0].n_findings == 0


# As the user runs it.

def write_mesh(path: Path, quads, groups) -> None:
    path.write_text(quad_obj(quads, groups))


def test_baseline_end_to_end(tmp_path):
    mesh = tmp_path / "prop.obj"
    write_mesh(mesh, QUADS, GROUPS)
    assert run("check", "prop.obj", cwd=tmp_path).returncode == 1
    written = run("check", "--write-baseline", "known.json", "prop.obj", cwd=tmp_path)
    assert written.returncode == 0, written.stderr
    assert "3 findings" in written.stderr
    clean = run("check", "--baseline", "known.json", "prop.obj", cwd=tmp_path)
    assert clean.returncode == 0 and "No new findings (1 file checked, 3 baselined)." in clean.stdout

    # Reorder the faces (and with them the lines): still clean.
    order = [3, 1, 0, 2]
    write_mesh(mesh, [QUADS[i] for i in order], [GROUPS[i] for i in order])
    reordered = run("check", "--baseline", "known.json", "--format", "json", "prop.obj", cwd=tmp_path)
    assert reordered.returncode == 0, reordered.stdout
    assert json.loads(reordered.stdout)["summary"]["baselined"] == 3

    # Add one bad quad: exactly one new finding, and it is the new quad.
    added = (trapezoid(0.25, 9), UNIT_UV)
    write_mesh(mesh, [QUADS[i] for i in order] + [added], [GROUPS[i] for i in order] + ["body"])
    result = run("check", "--baseline", "known.json", "--format", "json", "prop.obj", cwd=tmp_path)
    assert result.returncode == 1
    (finding,) = json.loads(result.stdout)["findings"]
    assert finding["face"] == 4 and finding["group"] == "body"


def test_baseline_from_another_folder_and_bad_baseline_file(tmp_path):
    (tmp_path / "assets").mkdir()
    write_mesh(tmp_path / "assets" / "prop.obj", QUADS, GROUPS)
    assert run("check", "--write-baseline", "ci/known.json", "assets", cwd=tmp_path).returncode == 2  # no ci/
    (tmp_path / "ci").mkdir()
    assert run("check", "--write-baseline", "ci/known.json", "assets", cwd=tmp_path).returncode == 0
    entries = json.loads((tmp_path / "ci" / "known.json").read_text())["entries"]
    assert {e["path"] for e in entries} == {"../assets/prop.obj"}
    assert run("check", "--baseline", "../ci/known.json", "prop.obj", cwd=tmp_path / "assets").returncode == 0
    (tmp_path / "ci" / "bad.json").write_text("{}")
    result = run("check", "--baseline", "ci/bad.json", "assets", cwd=tmp_path)
    assert result.returncode == 2 and "not a valid baseline" in result.stderr and "Traceback" not in result.stderr

