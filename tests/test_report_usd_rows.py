"""The report's USD rows name the prim and the face within it as ``affinity check`` does (issue 55), and
``#prim=/A/B&face=F`` flies to that face; no source-line column for USD rows.

The truth for the rows is ``affinity check --format json`` on the same stage; for the link, the 3-D view's
face id pass in headless Chromium (the face the link names covers pixels and is the one selected).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from helpers.chromium import CHROMIUM, WEBGL_FLAGS, DevTools, evaluate, open_page
from helpers.cli import run
from helpers.usd_studio import studio_asset

pytest.importorskip("pxr", reason="needs the usd extra (usd-core)")


@pytest.fixture(scope="module")
def studio_report(tmp_path_factory) -> tuple[Path, dict]:
    folder = tmp_path_factory.mktemp("studio")
    studio_asset(folder)
    built = run("report", "-q", "set.usda", "-o", "report.html", cwd=folder)
    assert built.returncode == 0, built.stderr
    checked = run("check", "--no-cache", "--isolated", "--format", "json", "set.usda", cwd=folder)
    return folder / "report.html", json.loads(checked.stdout)


def _view_data(page: str) -> dict:
    script = re.search(r'<figure class="view3d" data-view="3d".*?<script type="application/json">(.*?)</script>',
                       page, re.S)
    return json.loads(script.group(1))


def test_the_report_rows_name_prim_and_face_as_check_does(studio_report):
    report, checked = studio_report
    page = report.read_text()
    data = _view_data(page)
    rows = {(row["code"], row["prim"], row["prim_face"]) for row in data["findings"]}
    assert rows == {(f["code"], f["prim"], f["face"]) for f in checked["findings"]}
    starts = dict(zip(data["prims"]["names"], data["prims"]["starts"]))
    assert all(row["face"] == starts[row["prim"]] + row["prim_face"] for row in data["findings"])
    findings_table = page[page.index('<section class="section findings"'):]
    findings_table = findings_table[:findings_table.index("</table>")]
    for f in checked["findings"]:
        assert f'<span class="mono">{f["prim"]}</span> face {f["face"]} ·' in findings_table
    assert "line 0" not in findings_table


@pytest.mark.skipif(CHROMIUM is None, reason="no chromium installed")
def test_a_link_naming_prim_and_face_flies_to_it(studio_report):
    report, checked = studio_report
    data = _view_data(report.read_text())
    finding = checked["findings"][0]
    face = dict(zip(data["prims"]["names"], data["prims"]["starts"]))[finding["prim"]] + finding["face"]
    browser = DevTools(report.parent / "profile", WEBGL_FLAGS)
    try:
        session = open_page(browser, report.as_uri() + f"#prim={finding['prim']}&face={finding['face']}", 1280, 1000)
        evaluate(browser, session, "Promise.all(affinityViews.map(v => v.ready))")
        evaluate(browser, session, "new Promise(r => setTimeout(r, 1000))")  # the flight takes 0.45 s
        assert evaluate(browser, session, "affinityViews.map(v => v.selected)") == [face]
        cells = evaluate(browser, session, "Array.from(document.querySelectorAll('.view3d-findings thead th'))"
                                           ".map(th => th.textContent)")
        assert cells == ["level", "rule", "face", "value", "prim"]
        evaluate(browser, session, "affinityViews[0].toUrl()")
        assert f"prim={finding['prim']}&face={finding['face']}&" in evaluate(browser, session, "location.hash")
    finally:
        browser.close()


def test_a_report_over_the_stage_and_its_geometry_layer_gives_the_mesh_once(tmp_path):
    """As ``affinity check`` does over the same files: the set (two referencing prims) has the findings, the
    geometry layer none."""
    studio_asset(tmp_path)
    built = run("report", "-q", "set.usda", "assets/Piece/Piece_geom.usd", "-o", "report.html", cwd=tmp_path)
    assert built.returncode == 0, built.stderr
    checked = json.loads(run("check", "--no-cache", "--isolated", "--format", "json", "set.usda",
                              "assets/Piece/Piece_geom.usd", cwd=tmp_path).stdout)
    assert {f["path"] for f in checked["findings"]} == {"set.usda"}
    page = (tmp_path / "report.html").read_text()
    views = [json.loads(body) for body in re.findall(
        r'<figure class="view3d" data-view="3d".*?<script type="application/json">(.*?)</script>', page, re.S)]
    assert [{(row["prim"], row["prim_face"]) for row in view["findings"]} for view in views] == \
        [{(f["prim"], f["face"]) for f in checked["findings"]}, set()]
