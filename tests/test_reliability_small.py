"""The smaller items of issue 53, each as a user meets it: GitHub annotations carry no raw ESC; USD attributes of
the wrong type are one Q901 line; trimesh's points_emptyascii.ply layout reads; a selection that leaves no rule is
a usage error; JUnit leaves info findings out unless asked; ``affinity view`` colours by the attribute with
findings; ``affinity stability`` writes files only where told, and says the command that made them; the README's
fix example writes beside the working directory, not into the package."""

from __future__ import annotations

import io
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import SQUARE, TRAPEZOID, run, write
from helpers.quads import hits

from affinity.findings import FileReport
from affinity.output import CheckRun, github
from affinity.settings import Settings

ROOT = Path(__file__).resolve().parents[1]


def test_github_annotations_escape_esc_and_other_controls():
    report = FileReport("evil\x1b[31m.obj", counts={"faces": 1, "quads": 1, "triangles": 0, "ngons": 0},
                        group_names=["g\x07roup"], hits=[hits("Q101", [0], [3], [4.0])])
    out = io.StringIO()
    github.write(CheckRun([report], Settings()), out)
    text = out.getvalue()
    assert "\x1b" not in text and "\x07" not in text
    assert "file=evil%1B[31m.obj" in text


@pytest.mark.parametrize(("attribute", "line"), [
    ('string points = "hello"', "/m: points holds str values, not 3-component values"),
    ('point3f[] points = [(0,0,0),(1,0,0),(1,1,0),(0,1,0)]\n    string[] faceVertexCounts = ["a"]',
     "/m: faceVertexCounts holds StringArray values, not numbers"),
    ('point3f[] points = [(0,0,0),(1,0,0),(1,1,0),(0,1,0)]\n'
     '    string[] primvars:st = ["a", "b", "c", "d"] (interpolation = "vertex")',
     "/m: primvars:st holds StringArray values, not 2-component values"),
])
def test_usd_attributes_of_the_wrong_type_are_one_q901_line(tmp_path, attribute, line):
    pytest.importorskip("pxr")
    counts = "" if "faceVertexCounts" in attribute else "    int[] faceVertexCounts = [4]\n"
    stage = write(tmp_path, "bad.usda", f'#usda 1.0\ndef Mesh "m" {{\n    {attribute}\n{counts}'
                                        "    int[] faceVertexIndices = [0, 1, 2, 3]\n}\n")
    done = run("check", str(stage))
    assert done.returncode == 2
    assert done.stderr.splitlines() == [f"{stage}:0: Q901 unreadable: {line}"]


#: trimesh's models/points_emptyascii.ply (MIT licence): 13 vertex lines under a header that declares 12, a
#: trailing space on each, no newline after the last.
POINTS_EMPTYASCII = (
    "ply\nformat ascii 1.0\ncomment VCGLIB generated\nelement vertex 12\nproperty float x\nproperty float y\n"
    "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
    + " \n".join(f"-0.0{x} -0.0138{y} 0.038{z}" for x, y, z in [
        ("10441", "88", "2"), ("10369", "88", "2"), ("10296", "88", "2"), ("10223", "88", "2"),
        ("1015", "88", "2"), ("10078", "88", "2"), ("10005", "88", "2"), ("09932", "88", "2"),
        ("09859", "88", "2"), ("09786", "88", "2"), ("09765", "61", "4"), ("09691", "61", "4"),
        ("09618", "61", "4")]))


def test_trimesh_points_emptyascii_layout_reads_as_a_point_cloud(tmp_path):
    """No faces: skipped as no-mesh (as every point cloud), not unreadable at a line past the data."""
    path = write(tmp_path, "points_emptyascii.ply", POINTS_EMPTYASCII)
    done = run("check", str(path))
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines() == [f"{path}: skipped (no-mesh)"]


def test_a_data_line_past_the_declared_elements_is_left_with_a_note(tmp_path):
    """The rows the header declares are the mesh, as trimesh reads them (the second, independent reader)."""
    trimesh = pytest.importorskip("trimesh")
    from affinity.loaders import load

    text = ("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n2 0 0\n2 1 0\n0 1 0\n"
            "4 0 1 2 3\n9 9 9")
    path = write(tmp_path, "extra.ply", text)
    mesh = load(path)
    theirs = trimesh.load(path, process=False)
    assert np.array_equal(mesh.positions, np.asarray(theirs.vertices))
    assert mesh.n_faces == 1 and mesh.face_line.tolist() == [14]
    assert mesh.notes == ["1 data line after the elements the header declares (from line 15) not read"]


def test_a_selection_that_leaves_no_rule_is_a_usage_error(tmp_path):
    """Exit 2, not a silent pass: a gate that checks nothing would pass every asset."""
    path = write(tmp_path, "t.obj", TRAPEZOID)
    done = run("check", "--select", "Q101", "--ignore", "Q101", str(path))
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.splitlines() == [
        "affinity check: error: the selection leaves no rule to check (select Q101; ignore Q101)"]
    assert run("check", "--select", "Q101", "--ignore", "Q102", str(path)).returncode == 1


def test_junit_leaves_info_findings_out_unless_asked(tmp_path):
    """Q101 as info (levels in the configuration): JUnit without --level lists the file as one passing case
    and nothing of the finding; with --level info the finding is a testcase; the exit code is the same."""
    (tmp_path / "affinity.toml").write_text('[levels]\nQ101 = "info"\n')
    write(tmp_path, "t.obj", TRAPEZOID)
    default = run("check", "--format", "junit", "t.obj", cwd=tmp_path)
    asked = run("check", "--format", "junit", "--level", "info", "t.obj", cwd=tmp_path)
    assert default.returncode == asked.returncode == 0
    cases = lambda xml: [case.get("name") for case in ET.fromstring(xml).iter("testcase")]
    assert [name for name in cases(asked.stdout) if name.startswith("Q101")] == ["Q101 uv-disaffine face 0"]
    assert not any(name.startswith("Q101") for name in cases(default.stdout))
    assert "Q101" in run("check", "--format", "json", "t.obj", cwd=tmp_path).stdout  # still found


def test_view_colours_a_vertex_coloured_mesh_by_the_attribute_with_findings(tmp_path):
    """Clean uv, disaffine vertex colours (a corner off by 0.5 from the affine field): the colour score."""
    from affinity.commands.view import _scores
    from affinity.loaders import load

    colours = ["0 0 0", "0.2 0.2 0.2", "0.9 0.9 0.9", "0.2 0.2 0.2"]
    text = SQUARE.replace("v 0 0 0\n", f"v 0 0 0 {colours[0]}\n").replace("v 1 0 0\n", f"v 1 0 0 {colours[1]}\n")
    text = text.replace("v 1 1 0\n", f"v 1 1 0 {colours[2]}\n").replace("v 0 1 0\n", f"v 0 1 0 {colours[3]}\n")
    path = write(tmp_path, "terrain.obj", text)
    mesh = load(path)
    assert _scores(mesh, str(path), None).code == "Q102"
    assert _scores(mesh, str(path), "uv").code == "Q101"
    clean = write(tmp_path, "clean.obj", SQUARE)
    assert _scores(load(clean), str(clean), None).code == "Q101"  # nothing flagged: the first attribute


def test_stability_writes_only_where_told_and_names_its_command(tmp_path):
    pytest.importorskip("mpmath")
    done = run("stability", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert list(tmp_path.iterdir()) == [] and "mean_value float64" in done.stdout
    out = tmp_path / "out"
    assert run("stability", "-o", str(out), cwd=tmp_path).returncode == 0
    page = (out / "stability.md").read_text()
    assert "Generated by `affinity stability` in" in page and "--float32`" not in page.split("## ")[0]


def test_readme_fix_example_writes_nothing_into_the_package():
    readme = (ROOT / "README.md").read_text()
    fixes = [line for line in re.findall(r"^affinity fix .*$", readme, re.M) if "--dry-run" not in line]
    assert fixes and all(" -o " in line for line in fixes)
    assert "affinity check affinity/data/demo/trapezoid.fixed.obj" not in readme


def test_docs_pipeline_has_no_broken_fragment():
    text = (ROOT / "docs" / "pipeline.md").read_text()
    assert "\n\n`unit`; a Q101 finding" not in text  # a paragraph that began mid-sentence
    assert text.count("`--jobs N` checks files in parallel") == 1


def test_readme_says_a_clone_without_shared_skips_those_tests():
    assert "a clone without that folder\nskips them" in (ROOT / "README.md").read_text()
