"""A mesh that several prims reference from one geometry layer is reported once, where it is authored.

The truth is the geometry layer checked on its own (one prim, no references): the stage that
references it four times must give the same faces and values, once, naming the four prims.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers.cli import run
from helpers.sarif import assert_valid
from helpers.usd_stages import BIG, POINTS, SMALL, ST, referenced_stage

pytest.importorskip("pxr", reason="needs the usd extra (usd-core)")

PRIMS = [f"/Set/{name}/Knight" for name in "ABCD"]


def check_json(*paths: Path) -> dict:
    result = run("check", "--no-cache", "--isolated", "--format", "json", *map(str, paths))
    assert result.returncode == 1, result.stderr
    return json.loads(result.stdout)


def test_four_prims_referencing_one_layer_report_each_finding_once(tmp_path):
    stage = referenced_stage(tmp_path)
    alone = check_json(tmp_path / "knight.usda")["findings"]
    findings = check_json(stage)["findings"]
    assert [(f["face"], f["level"]) for f in alone] == [(0, "error"), (1, "warning")]
    assert [(f["code"], f["face"], f["level"], f["value"]) for f in findings] == \
        [(f["code"], f["face"], f["level"], f["value"]) for f in alone]
    for f in findings:
        assert (f["prim"], f["prims"]) == (PRIMS[0], PRIMS)
        assert (Path(f["layer"]), f["layer_prim"]) == (tmp_path / "knight.usda", "/Knight")
        assert "prim_values" not in f  # the four measure alike


def test_prims_with_their_own_uv_carry_the_worst_and_each_value(tmp_path):
    """Prim C authors face 1's uv as face 0's bigger square (an error), B face 0's as the small square:
    the finding takes the worst and lists each prim's value; truth is each variant checked alone."""
    bigger = [*ST[:4], *BIG, *ST[8:]]
    smaller = [*SMALL, *ST[4:]]
    stage = referenced_stage(tmp_path, override_st={"B": smaller, "C": bigger})
    big_value = check_json(tmp_path / "knight.usda")["findings"][0]["value"]
    small_value = check_json(tmp_path / "knight.usda")["findings"][1]["value"]
    face0, face1 = check_json(stage)["findings"]
    assert (face0["face"], face0["level"], face0["value"]) == (0, "error", big_value)
    assert face0["prim_values"] == [big_value, pytest.approx(small_value), big_value, big_value]
    assert (face1["face"], face1["level"], face1["value"]) == (1, "error", pytest.approx(big_value))
    assert face1["prim_values"] == [small_value, small_value, pytest.approx(big_value), small_value]


def test_text_and_sarif_name_the_layer_and_the_prims(tmp_path):
    stage = referenced_stage(tmp_path)
    text = run("check", "--no-cache", "--isolated", str(stage)).stdout.splitlines()
    assert len([line for line in text if "Q101" in line]) == 2
    assert all(f"referenced by {', '.join(PRIMS)}]" in line and "knight.usda:/Knight" in line
               for line in text if "Q101" in line)
    result = run("check", "--no-cache", "--isolated", "--format", "sarif", str(stage), cwd=tmp_path)
    log = json.loads(result.stdout)
    assert_valid(log)
    results = log["runs"][0]["results"]
    assert len(results) == 2
    for r in results:
        assert [loc["fullyQualifiedName"] for loc in r["locations"][0]["logicalLocations"]] == PRIMS
        assert r["relatedLocations"][0]["physicalLocation"]["artifactLocation"]["uri"] == "knight.usda"


def test_a_run_over_the_geometry_layer_and_the_stage_reports_the_mesh_once(tmp_path):
    """The geometry layer and the stage referencing it, checked in one run (design.md, Clarifications): the
    mesh's findings come once, from the stage (four referencing prims against one), as the stage alone gives
    them, and list the layer's own prim too."""
    stage = referenced_stage(tmp_path)
    alone = check_json(stage)["findings"]
    findings = check_json(stage, tmp_path / "knight.usda")["findings"]
    assert [(Path(f["path"]).name, f["face"], f["value"]) for f in findings] == \
        [(Path(f["path"]).name, f["face"], f["value"]) for f in alone]
    assert all(f["prims"] == [*PRIMS, f"{tmp_path / 'knight.usda'}:/Knight"] for f in findings)


def test_a_prim_that_authors_its_own_points_is_its_own_mesh(tmp_path):
    """Prim B moves a point of the referenced mesh: its geometry is authored in set.usda, so it is reported
    on its own (with its own value for the changed quad), and the other three stay one report."""
    from pxr import Usd, UsdGeom

    stage_path = referenced_stage(tmp_path)
    stage = Usd.Stage.Open(str(stage_path))
    moved = [(x, y + 0.5 * (i == 5), z) for i, (x, y, z) in enumerate(POINTS)]  # face 0's corner (-1, 1)
    UsdGeom.Mesh(stage.GetPrimAtPath("/Set/B/Knight")).GetPointsAttr().Set(moved)
    stage.GetRootLayer().Save()
    findings = check_json(stage_path)["findings"]
    by_prim = {}
    for f in findings:
        by_prim.setdefault(f["prim"], []).append(f)
    assert sorted(by_prim) == ["/Set/A/Knight", "/Set/B/Knight"]
    assert [f["prims"] for f in by_prim["/Set/A/Knight"]] == [[PRIMS[0], *PRIMS[2:]]] * 2
    assert all("prims" not in f for f in by_prim["/Set/B/Knight"])
    assert by_prim["/Set/B/Knight"][0]["value"] != by_prim["/Set/A/Knight"][0]["value"]


@pytest.mark.parametrize("fmt", ["json", "sarif", "text"])
def test_a_merge_of_shards_reports_shared_geometry_as_one_run(tmp_path, fmt):
    """affinity merge reads layer, prims and each prim's values back from the shards' JSON."""
    referenced_stage(tmp_path, override_st={"B": [*SMALL, *ST[4:]]})
    (tmp_path / "other").mkdir()
    referenced_stage(tmp_path / "other")
    options = ["--no-cache", "--isolated", "set.usda", "other/set.usda"]
    whole = run("check", *options, "--format", fmt, cwd=tmp_path)
    for k in (1, 2):
        result = run("check", *options, "--shard", f"{k}/2", "--format", "json", "-o", f"shard{k}.json", cwd=tmp_path)
        assert result.returncode in (0, 1), result.stderr
    merged = run("merge", "shard1.json", "shard2.json", "--format", fmt, cwd=tmp_path)
    assert (merged.returncode, merged.stdout) == (whole.returncode, whole.stdout)
    assert "prim_values" in whole.stdout or fmt == "text"


def test_the_result_cache_keeps_shared_geometry(tmp_path, monkeypatch):
    monkeypatch.setenv("AFFINITY_CACHE_DIR", str(tmp_path / "cache"))
    stage = referenced_stage(tmp_path, override_st={"B": [*SMALL, *ST[4:]]})
    fresh = run("check", "--no-cache", "--isolated", "--format", "json", str(stage)).stdout
    stored, cached = (run("check", "--isolated", "--format", "json", str(stage)).stdout for _ in range(2))
    assert fresh == stored == cached and '"prim_values"' in cached
