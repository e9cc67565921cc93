"""Severity by visibility, the texel note, the run cap of SARIF/GitHub output and the PLY point cloud skip
(issue 26). Expected values come from the trapezoid's closed form: a trapezoid with bottom 2 and top w
carrying the unit square of uv shifts the texture by (1 - r) / (1 + sqrt r)^2 of its width at worst,
r = w / 2 (the Q101 rule page)."""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import TRAPEZOID, run, write
from helpers.quads import trapezoids
from helpers.sarif import assert_valid

from affinity.config import ConfigError, read_config
from affinity.findings import FileReport, RuleHits
from affinity.output import CheckRun, github, sarif
from affinity.settings import Settings

ROOT = Path(__file__).resolve().parents[1]

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib


def texels(width: float, size: int = 1024) -> float:
    r = width / 2
    return size * (1 - r) / (1 + math.sqrt(r)) ** 2


def levels_of(result) -> list[tuple[float, str]]:
    return [(f["value"], f["level"]) for f in json.loads(result.stdout)["findings"]]


def test_a_finding_is_an_error_only_where_the_crease_is_visible(tmp_path):
    widths = [1.992, 1.98, 1.97, 1.0]  # 1.03, 2.6, 3.9 and 176 texels
    path = str(write(tmp_path, "steps.obj", trapezoids(widths)))
    result = run("check", "--format", "json", path)
    assert result.returncode == 1
    found = levels_of(result)
    assert [v for v, _ in found] == pytest.approx([texels(w) for w in widths], rel=1e-6)
    assert [level for _, level in found] == ["warning" if texels(w) <= 2 else "error" for w in widths]


def test_the_mild_crease_passes_the_default_gate_and_fails_with_fail_on_warning(tmp_path):
    path = str(write(tmp_path, "mild.obj", trapezoids([1.992])))
    assert texels(1.992) == pytest.approx(1.026, abs=1e-3)
    assert run("check", path).returncode == 0
    assert run("check", "--fail-on", "warning", path).returncode == 1


def test_the_demo_trapezoid_is_an_error():
    doc = json.loads(run("check", "--demo", "--format", "json").stdout)
    (trapezoid,) = [f for f in doc["findings"] if f["path"].endswith("trapezoid.obj")]
    assert trapezoid["level"] == "error" and trapezoid["value"] == pytest.approx(texels(1.0), rel=1e-6)


def test_the_visibility_threshold_is_a_setting(tmp_path):
    path = str(write(tmp_path, "steps.obj", trapezoids([1.97, 1.0])))  # 3.9 and 176 texels
    (tmp_path / "affinity.toml").write_text('[levels]\nQ101 = {error = 100}\nQ302 = "warning"\n')
    assert [level for _, level in levels_of(run("check", "--format", "json", path))] == ["warning", "error"]
    (tmp_path / "affinity.toml").write_text('[levels]\nQ101 = "warning"\n')  # one level for all, as before
    result = run("check", "--format", "json", path)
    assert [level for _, level in levels_of(result)] == ["warning", "warning"] and result.returncode == 0


@pytest.mark.parametrize("table, message", [
    ("Q101 = {error = nan}", "finite"),
    ("Q101 = {warning = 2}", "{error = number}"),
    ("Q204 = {error = 2}", "not a rule with a threshold"),
    ("Q101 = \"loud\"", "expected a rule code"),
])
def test_bad_visibility_settings_are_usage_errors(tmp_path, table, message):
    config = tmp_path / "affinity.toml"
    config.write_text(f"[levels]\n{table}\n")
    with pytest.raises(ConfigError, match=message.replace("{", r"\{").replace("}", r"\}")):
        read_config(config)


def test_show_settings_prints_both_thresholds_as_a_valid_config(tmp_path):
    (tmp_path / "affinity.toml").write_text('[thresholds]\nQ102 = 3\n[levels]\nQ103 = {error = 12}\nQ302 = "warning"\n')
    shown = run("check", "--show-settings", cwd=tmp_path).stdout
    parsed = tomllib.loads(shown)
    assert parsed["thresholds"]["Q101"] == 0.5 and parsed["thresholds"]["Q102"] == 3.0
    assert parsed["levels"]["Q101"] == {"error": 2.0} and parsed["levels"]["Q103"] == {"error": 12.0}
    assert parsed["levels"]["Q302"] == "warning" and parsed["levels"]["Q204"] == "error"
    again = tmp_path / "again"
    again.mkdir()
    (again / "affinity.toml").write_text(shown)
    assert run("check", "--show-settings", cwd=again).stdout.split("\n", 3)[3] == shown.split("\n", 3)[3]


def test_the_worst_texel_finding_says_the_texture_size_was_assumed(tmp_path):
    """On the worst finding: the one text output prints first and every cap keeps."""
    path = str(write(tmp_path, "steps.obj", trapezoids([1.0, 1.2, 0.8])))
    findings = json.loads(run("check", "--format", "json", path).stdout)["findings"]
    worst = max(range(len(findings)), key=lambda i: findings[i]["value"])
    messages = [f["message"] for f in findings]
    assert "assumed 1024x1024 texture" in messages[worst] and "--texture-size" in messages[worst]
    assert sum("assumed" in m for m in messages) == 1, "once per file"
    sized = json.loads(run("check", "--format", "json", "--texture-size", "512", path).stdout)["findings"]
    assert "assumed 512x512" in sized[worst]["message"] and sized[0]["value"] == pytest.approx(texels(1.0, 512))


def test_a_known_texture_needs_no_note(tmp_path):
    from PIL import Image

    Image.new("RGB", (256, 128)).save(tmp_path / "wood.png")
    (tmp_path / "wood.mtl").write_text("newmtl wood\nmap_Kd wood.png\n")
    write(tmp_path, "crate.obj", "mtllib wood.mtl\nusemtl wood\n" + TRAPEZOID)
    (finding,) = json.loads(run("check", "--format", "json", "crate.obj", cwd=tmp_path).stdout)["findings"]
    assert "assumed" not in finding["message"]


# The run cap of SARIF and GitHub output.

def test_default_sarif_keeps_5000_of_a_run_over_several_files_a_fair_share_each(tmp_path):
    """6,600 errors in three files: each file keeps its worst third of the 5,000 (1,667, 1,667, 1,666)."""
    rng = np.random.default_rng(3)
    widths = [rng.uniform(0.2, 0.6, 2200) for _ in range(3)]  # 6,600 flagged quads in three files, all errors
    assert min(texels(w) for ws in widths for w in ws) > 2.0
    paths = [str(write(tmp_path, f"part{i}.obj", trapezoids(w))) for i, w in enumerate(widths)]
    result = run("check", "--format", "sarif", *paths, cwd=tmp_path)
    assert result.returncode == 1
    log = json.loads(result.stdout)
    assert_valid(log)
    (sarif_run,) = log["runs"]
    results = sarif_run["results"]
    assert len(results) == 5000
    for i, (ws, share) in enumerate(zip(widths, [1667, 1667, 1666])):
        kept = [r["properties"]["value"] for r in results
                if r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == f"part{i}.obj"]
        expected = np.sort([texels(w) for w in ws])[::-1][:share]
        np.testing.assert_allclose(np.sort(kept)[::-1], expected, rtol=1e-6)
    (note,) = sarif_run["invocations"][0]["toolExecutionNotifications"]
    assert "truncated" in note["message"]["text"] and "left out: 1,600 of 6,600 error" in note["message"]["text"]
    assert "truncated" in result.stderr and len(result.stderr.strip().splitlines()) == 1
    capped = json.loads(run("check", "--format", "sarif", "--max-findings", "2000", *paths, cwd=tmp_path).stdout)
    assert len(capped["runs"][0]["results"]) == 6000, "--max-findings replaces the run cap (per file and rule)"


def test_sarif_keeps_every_error_of_a_small_file_beside_a_big_one(tmp_path):
    """The issue's folder: a big file with thousands of errors and warnings must not crowd out a small one's
    errors, and no warning is kept while an error is dropped."""
    rng = np.random.default_rng(5)
    big = np.concatenate([rng.uniform(0.2, 0.6, 5500), rng.uniform(1.986, 1.994, 1500)])  # errors, then warnings
    small = np.concatenate([rng.uniform(0.5, 0.9, 7), rng.uniform(1.986, 1.994, 30)])
    small_values, big_values = (np.array([texels(w) for w in ws]) for ws in (small, big))
    assert (small_values > 2.0).sum() == 7 and (big_values <= 2.0).sum() == 1500
    write(tmp_path, "car.obj", trapezoids(big))
    write(tmp_path, "cow.obj", trapezoids(small))
    result = run("check", "--format", "sarif", ".", cwd=tmp_path)
    results = json.loads(result.stdout)["runs"][0]["results"]
    by_file = {}
    for r in results:
        by_file.setdefault(r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"], []).append(r["level"])
    assert by_file["cow.obj"].count("error") == 7, "all of the small file's errors"
    assert len(results) == 5000 and {level for levels in by_file.values() for level in levels} == {"error"}
    assert "left out: 507 of 5,507 error, 1,530 of 1,530 warning" in result.stderr


def test_sarif_under_the_cap_says_nothing_of_truncation(tmp_path):
    path = str(write(tmp_path, "few.obj", trapezoids([1.0, 1.5])))
    result = run("check", "--format", "sarif", path, cwd=tmp_path)
    log = json.loads(result.stdout)
    assert_valid(log)
    assert len(log["runs"][0]["results"]) == 2 and log["runs"][0]["invocations"][0]["toolExecutionNotifications"] == []
    assert "truncated" not in result.stderr


def _hits(code: str, values: list[float], threshold: float, level: str, error_above=None) -> RuleHits:
    n = len(values)
    return RuleHits(code, np.arange(n), np.arange(n) + 10, np.array(values, dtype=float), threshold,
                    np.zeros(n, dtype=np.int32), level=level, error_above=error_above)


def test_the_cap_keeps_errors_before_warnings_whatever_the_ratio(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    reports = [
        FileReport("a.obj", hits=[_hits("Q102", [7.0, 7.5], 0.1, "warning", error_above=8.0)]),  # ratios 70, 75
        FileReport("b.obj", hits=[_hits("Q101", [3.0], 0.5, "warning", error_above=2.0)]),  # ratio 6, an error
    ]
    check_run = CheckRun(reports, Settings(), run_cap=2)
    out = io.StringIO()
    sarif.write(check_run, out)
    results = json.loads(out.getvalue())["runs"][0]["results"]
    assert sorted((r["ruleId"], r["level"], r["properties"]["value"]) for r in results) == [
        ("Q101", "error", 3.0), ("Q102", "warning", 7.5)]
    assert "worst 2 of 3" in capsys.readouterr().err

    out = io.StringIO()
    github.write(CheckRun(reports, Settings(), run_cap=1), out)
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("::error file=b.obj,line=10") and "title=truncated" in lines[1] and len(lines) == 2


# A PLY point cloud.

def test_a_ply_with_vertices_and_no_faces_is_skipped(tmp_path):
    path = str(write(tmp_path, "scan.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                          "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n"))
    result = run("check", "--format", "json", path)
    assert result.returncode == 0 and "Traceback" not in result.stderr
    (entry,) = json.loads(result.stdout)["files"]
    assert entry["skipped"] == "no-mesh"
    assert run("check", "--fail-on-skip", path).returncode == 2
    obj = str(write(tmp_path, "points.obj", "v 0 0 0\nv 1 0 0\n"))
    assert [f["code"] for f in json.loads(run("check", "--format", "json", obj).stdout)["findings"]] == ["Q205"]


# Calibration: the default gate against the visibility line.

def _calibration():
    import importlib.util

    spec = importlib.util.spec_from_file_location("calibration", ROOT / "benchmarks" / "calibration.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("k, exit_code", [(8, 1), (16, 0)])
def test_a_subdivided_trapezoid_fails_only_where_its_worst_quad_shows_the_crease(k, exit_code, tmp_path):
    """Sub-quad row j spans widths 2 - j/k to 2 - (j+1)/k under a uv square 1/k wide: an affine image of
    the trapezoid of side ratio r = (2 - (j+1)/k) / (2 - j/k), so its error is 1024/k (1 - r) / (1 + sqrt r)^2."""
    path = str(write(tmp_path, f"sub{k}.obj", _calibration().subdivided_trapezoid(k)))
    result = run("check", "--format", "json", path)
    values = [f["value"] for f in json.loads(result.stdout)["findings"]]
    ratios = [(2 - (j + 1) / k) / (2 - j / k) for j in range(k)]
    expected = [1024 / k * (1 - r) / (1 + math.sqrt(r)) ** 2 for r in ratios]
    assert max(values) == pytest.approx(max(expected), rel=1e-6)
    assert (max(expected) > 2) == bool(exit_code) and result.returncode == exit_code


def test_the_readme_calibration_table_is_what_the_default_gate_does(shared_meshes):
    """Each row of the generated table: exit 1 exactly where the largest uv error reaches 2 texels or another
    rule found an error; and the shared meshes exit today as the table says."""
    rows = json.loads((ROOT / "reports" / "bench" / "calibration.json").read_text())
    assert len(rows) >= 10
    for row in rows:
        visible = row["largest"] is not None and row["largest"] > 2
        assert row["exit"] == int(visible or row["others"] > 0), row
        assert (row["error"] > 0) == visible, row
    for row in rows:
        if (shared_meshes / row["mesh"]).is_file():
            assert run("check", "--isolated", str(shared_meshes / row["mesh"])).returncode == row["exit"], row["mesh"]
