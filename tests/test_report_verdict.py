"""The report opens with the verdict (issue 38): pass or fail at the level that fails ``affinity check`` with the
same settings, counts per level for the run and for each file, a level column in the findings tables, and
close-ups that show errors first. The page is parsed; the expected counts come from the trapezoids' closed form.
"""

from __future__ import annotations

import math

from helpers.cli import run, write
from helpers.quads import trapezoids
from test_report import closeup_figures, mesh_article, parse, run_report, section


def texels(width: float, size: int = 1024) -> float:
    """The split's largest uv error on a trapezoid 2 wide at the bottom, ``width`` at the top, with the unit
    square as its uv: (1 - r) / (1 + sqrt r)^2 of the texture, r = width / 2 (tests/test_measures_error.py)."""
    r = width / 2
    return size * (1 - r) / (1 + math.sqrt(r)) ** 2


#: Above 2 texels an error, between 0.5 and 2 a warning.
CREASED = [0.3, 0.5, 1.0]  # 3 errors
MILD = [1.988, 1.99, 1.992, 1.994]  # 4 warnings


def levels_of(node) -> dict[str, int]:
    return {span.attrs["data-level"]: int(span.attrs["data-count"]) for span in node.find_all("span", "level")
            if "data-count" in span.attrs}


def test_the_report_states_the_verdict_of_the_run_and_of_each_file(tmp_path):
    assert all(texels(w) > 2 for w in CREASED) and all(0.5 < texels(w) < 2 for w in MILD)
    write(tmp_path, "creased.obj", trapezoids(CREASED + MILD))
    write(tmp_path, "mild.obj", trapezoids(MILD))
    result = run_report("creased.obj", "mild.obj", "-q", "-o", "out.html", "--max-views", "4", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    doc = parse(tmp_path / "out.html")
    (verdict,) = [p for p in doc.find_all("p", "verdict") if p.attrs.get("id") == "verdict"]
    assert verdict.attrs["data-verdict"] == "fails" and verdict.attrs["data-fail-on"] == "error"
    assert "Fails" in verdict.text() and levels_of(verdict) == {"error": 3, "warning": 8, "info": 0}
    assert run("check", "creased.obj", "mild.obj", cwd=tmp_path).returncode == 1, "the check agrees"

    creased, mild = mesh_article(doc, "creased.obj"), mesh_article(doc, "mild.obj")
    assert [a.find_all("span", "status")[0].text() for a in (creased, mild)] == ["fails", "passes"]
    (mild_line,) = mild.find_all("p", "verdict-levels")
    assert mild_line.text().startswith("Passes at") and levels_of(mild_line) == {"error": 0, "warning": 4, "info": 0}
    assert levels_of(creased.find_all("p", "verdict-levels")[0]) == {"error": 3, "warning": 4, "info": 0}

    files = section(doc, "summary").find_all("table", "files")[0].find_all("tr")
    header = [th.text() for th in files[0].find_all("th")]
    assert header[1:5] == ["Verdict", "Errors", "Warnings", "Info"]
    cells = [[td.text().strip() for td in row.find_all("td")][1:5] for row in files[1:]]
    assert cells == [["fails", "3", "4", "0"], ["passes", "0", "4", "0"]]

    findings = section(creased, "findings").find_all("table")[0]
    assert [th.text() for th in findings.find_all("th")][1] == "Level"
    (q101,) = findings.find_all("tr")[1:]
    assert levels_of(q101.find_all("td", "levels")[0]) == {"error": 3, "warning": 4}
    listed = [span.text() for span in q101.find_all("span", "level") if "data-count" not in span.attrs]
    assert listed == ["error"] * 3 + ["warning"] * 2, "the worst five, errors first"

    figures = closeup_figures(creased)
    assert figures and all(f.attrs["data-rule"] == "Q101" for f in figures)
    faces = [int(f.attrs["data-face"]) for f in figures]
    assert faces[:3] == [0, 1, 2], "the three errors take the first slots, the worst first"


def test_a_passing_run_says_it_passes_and_fail_on_warning_makes_it_fail(tmp_path):
    write(tmp_path, "mild.obj", trapezoids(MILD))
    for fail_on, expected in (("error", "passes"), ("warning", "fails")):
        result = run_report("mild.obj", "-q", "-o", f"{fail_on}.html", "--max-views", "0", "--fail-on", fail_on,
                            cwd=tmp_path)
        assert result.returncode == 0, result.stderr
        (verdict,) = [p for p in parse(tmp_path / f"{fail_on}.html").find_all("p", "verdict")]
        assert verdict.attrs["data-verdict"] == expected and levels_of(verdict)["warning"] == 4
        assert run("check", "--fail-on", fail_on, "mild.obj", cwd=tmp_path).returncode == (expected == "fails")
