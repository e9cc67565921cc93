"""`affinity check` as a user runs it: its exit code, stdout and stderr (``helpers.cli.run``)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from helpers.cli import SQUARE, TRAPEZOID, run, write

TEXT_LINE = re.compile(
    r"^(?P<path>.+):(?P<line>\d+):(?P<col>\d+): (?P<code>Q\d{3}) (?P<level>error|warning|info) (?P<name>[a-z-]+): .+ "
    r"\((?P<value>\S+) vs (?P<threshold>\S+) (?P<unit>[a-z ]+)\) \[face (?P<face>\d+)\]$"
)






def test_affine_square_is_clean(tmp_path):
    result = run("check", str(write(tmp_path, "square.obj", SQUARE)))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "No findings" in result.stdout


def test_trapezoid_is_flagged_with_ruff_style_line(tmp_path):
    path = write(tmp_path, "trapezoid.obj", "# a trapezoid\n" + TRAPEZOID)
    result = run("check", str(path))
    assert result.returncode == 1
    lines = [line for line in result.stdout.splitlines() if line.startswith(str(path))]
    assert len(lines) == 1, result.stdout
    match = TEXT_LINE.match(lines[0])
    assert match, lines[0]
    assert (match["line"], match["col"], match["code"], match["level"], match["name"]) == (
        "10", "1", "Q101", "error", "uv-disaffine")
    assert (match["value"], match["threshold"], match["unit"], match["face"]) == ("175.7", "0.5", "texels", "0")


def test_json_document_carries_every_field(tmp_path):
    path = write(tmp_path, "trapezoid.obj", TRAPEZOID)
    result = run("check", "--format", "json", str(path))
    assert result.returncode == 1
    doc = json.loads(result.stdout)
    assert doc["schema"] == "quad-affinity-check" and doc["version"] == 1
    (entry,) = doc["files"]
    assert entry == {"path": str(path), "faces": 1, "quads": 1, "triangles": 0, "ngons": 0, "findings": 1}
    (finding,) = doc["findings"]
    assert finding["code"] == "Q101" and finding["face"] == 0 and finding["line"] == 9
    assert finding["value"] > finding["threshold"] == 0.5
    assert set(finding) >= {"path", "line", "column", "code", "name", "face", "value", "threshold"}
    assert doc["summary"]["by_rule"] == {"Q101": 1}


def test_select_ignore_and_threshold(tmp_path):
    path = str(write(tmp_path, "trapezoid.obj", TRAPEZOID))
    assert run("check", "--ignore", "Q1", path).returncode == 0
    assert run("check", "--select", "Q2", path).returncode == 0
    assert run("check", "--select", "Q101", path).returncode == 1
    assert run("check", "--threshold", "1e6", path).returncode == 0
    assert run("check", "--threshold", "Q101=1e6", path).returncode == 0
    bad = run("check", "--threshold", "Q999=1", path)
    assert bad.returncode == 2 and "Q999" in bad.stderr and "Traceback" not in bad.stderr


def test_barycentric_measure_uses_paper_tolerance(tmp_path):
    path = str(write(tmp_path, "trapezoid.obj", TRAPEZOID))
    doc = json.loads(run("check", "--measure", "barycentric", "--format", "json", path).stdout)
    (finding,) = doc["findings"]
    assert finding["threshold"] == 0.01 and 0.01 < finding["value"] < 10


def test_statistics_counts_per_rule(tmp_path):
    path = str(write(tmp_path, "trapezoid.obj", TRAPEZOID))
    result = run("check", "--statistics", path)
    assert re.search(r"^\s+1\s+Q101\s+uv-disaffine\s+\[error\]$", result.stdout, re.M), result.stdout


def test_text_output_is_capped_per_rule(tmp_path):
    n = 29  # trapezoids (bottom 2 wide, top 1 wide), each with a unit-square uv
    vertices = "".join(
        f"v {3 * i} 0 0\nv {3 * i + 2} 0 0\nv {3 * i + 1.5} 1 0\nv {3 * i + 0.5} 1 0\n" for i in range(n)
    )
    uvs = "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    faces = "".join(f"f {4 * i + 1}/1 {4 * i + 2}/2 {4 * i + 3}/3 {4 * i + 4}/4\n" for i in range(n))
    path = write(tmp_path, "many.obj", vertices + uvs + faces)
    shown = run("check", str(path)).stdout
    assert len([line for line in shown.splitlines() if TEXT_LINE.match(line)]) == 20
    assert f"{path}: ... and {n - 20} more Q101 (use --verbose or --format json for all)" in shown
    verbose = run("check", "--verbose", str(path)).stdout
    assert len([line for line in verbose.splitlines() if TEXT_LINE.match(line)]) == n


BAD_INPUTS = {
    "empty.obj": b"",
    "junk.obj": bytes(range(256)) * 4,
    "nonutf8.obj": b"v 0 0 0\nv 1 0 0\nv 1 1 0\ng caf\xe9\xff\xfe\x00\nf 1 2 3\n",
    "nan.obj": b"v 0 0 0\nv 1 nan 0\nv 1 1 0\nf 1 2 3\n",
    "inf.obj": b"v 0 0 0\nv 1 0 inf\nv 1 1 0\nf 1 2 3\n",
    "zero_index.obj": b"v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n",
    "out_of_range.obj": b"v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n",
    "two_corners.obj": b"v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2\n",
    "truncated.obj": b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 3 5",
    "wrong.stl": b"solid x\nendsolid x\n",
    "truncated.ply": b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                     b"property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                     b"0 0 0\n1 0 0\n",
    "truncated.off": b"OFF\n4 1 0\n0 0 0\n1 0 0\n",
}


@pytest.mark.parametrize("name", sorted(BAD_INPUTS))
def test_bad_input_is_one_clear_line_and_exit_2(tmp_path, name):
    path = write(tmp_path, name, BAD_INPUTS[name])
    result = run("check", str(path))
    assert result.returncode == 2, (result.stdout, result.stderr)
    assert "Traceback" not in result.stderr
    errors = result.stderr.strip().splitlines()
    assert len(errors) == 1, result.stderr
    assert re.match(rf"^{re.escape(str(path))}:\d+: Q901 unreadable: .+", errors[0]), errors[0]


def test_bad_input_reports_the_offending_line(tmp_path):
    path = write(tmp_path, "bad.obj", BAD_INPUTS["out_of_range.obj"])
    assert run("check", str(path)).stderr.startswith(f"{path}:4: Q901")


def test_missing_path_and_empty_directory_are_usage_errors(tmp_path):
    for target in (tmp_path / "missing.obj", tmp_path):
        result = run("check", str(target))
        assert result.returncode == 2 and "Traceback" not in result.stderr
        assert str(target) in result.stderr
    assert run("check", cwd=tmp_path).returncode == 2, "no PATH checks ., and . has no meshes"


def test_one_bad_file_does_not_stop_a_directory_run(tmp_path):
    write(tmp_path, "a_bad.obj", BAD_INPUTS["nan.obj"])
    write(tmp_path, "b_trapezoid.obj", TRAPEZOID)
    write(tmp_path, "c_square.OBJ", SQUARE)
    write(tmp_path, "notes.txt", "not a mesh")
    result = run("check", "--format", "json", str(tmp_path))
    assert result.returncode == 2  # 2 wins over 1
    doc = json.loads(result.stdout)
    assert [Path(f["path"]).name for f in doc["files"]] == ["a_bad.obj", "b_trapezoid.obj", "c_square.OBJ"]
    assert "error" in doc["files"][0] and doc["files"][0]["line"] == 2
    assert [f["code"] for f in doc["findings"]] == ["Q101"]


def test_lfs_pointer_is_skipped_not_an_error(tmp_path):
    pointer = "version https://git-lfs.github.com/spec/v1\noid sha256:abc\nsize 123\n"
    path = write(tmp_path, "big.obj", pointer)
    result = run("check", "--format", "json", str(path))
    assert result.returncode == 0
    assert json.loads(result.stdout)["files"] == [{"path": str(path), "skipped": "lfs-pointer"}]
    assert "skipped" in run("check", str(path)).stderr


def test_vertices_without_faces_is_a_finding(tmp_path):
    path = write(tmp_path, "points.obj", "v 0 0 0\nv 1 0 0\n")
    result = run("check", "--format", "json", str(path))
    assert result.returncode == 0, "Q205 is a warning: the default gate fails on errors"
    assert [f["code"] for f in json.loads(result.stdout)["findings"]] == ["Q205"]
    assert run("check", "--fail-on", "warning", str(path)).returncode == 1


def test_demo_meshes_are_checked():
    result = run("check", "--demo", "--format", "json")
    doc = json.loads(result.stdout)
    assert result.returncode == 1
    codes = {f["code"] for f in doc["findings"]}
    assert {"Q101", "Q102"} <= codes


def test_counts_match_the_manifest_on_every_shared_mesh(shared_meshes):
    manifest = json.loads((shared_meshes / "MANIFEST.json").read_text())
    result = run("check", "--format", "json", *(str(shared_meshes / m["file"]) for m in manifest))
    assert result.returncode in (0, 1), result.stderr
    entries = {Path(f["path"]).name: f for f in json.loads(result.stdout)["files"]}
    for m in manifest:
        entry = entries[m["file"]]
        assert {k: entry[k] for k in ("faces", "quads", "triangles", "ngons")} == {
            k: m[k] for k in ("faces", "quads", "triangles", "ngons")
        }, m["file"]
