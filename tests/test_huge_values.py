"""Huge and non-finite numbers (issue 53): a coordinate or attribute beyond the loaders' bound
(:data:`affinity.loaders.numbers.LARGEST`, 1e75: the lint's squared cross products of edges stay finite
below 9.8e75) is one Q901 line naming file and line, never a RuntimeWarning; every JSON the tools write
(check --format json|sarif, merge, the report's data) parses with a strict parser.

The truth the strict parser stands for: RFC 8259 has no NaN or Infinity tokens (Python's json.loads takes
them unless ``parse_constant`` refuses).
"""

from __future__ import annotations

import io
import json
import re
import subprocess
import sys
import warnings

import numpy as np
import pytest
from helpers.cli import SQUARE, TRAPEZOID, run, write
from helpers.quads import hits

from affinity.findings import FileReport
from affinity.loaders.numbers import LARGEST
from affinity.output import CheckRun, sarif
from affinity.output import json as json_output
from affinity.settings import Settings


def strict_loads(text: str):
    """``text`` parsed as RFC 8259 JSON: NaN, Infinity and -Infinity are refused."""

    def refuse(constant):
        raise ValueError(f"not strict JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def quad(positions=((0, 0, 0), (1, 0, 0), (1.2, 1, 0), (0, 1, 0)), uv=((0, 0), (1, 0), (1, 1), (0, 1))) -> str:
    return ("".join(f"v {x} {y} {z}\n" for x, y, z in positions) + "".join(f"vt {u} {v}\n" for u, v in uv)
            + "f 1/1 2/2 3/3 4/4\n")


HUGE = {
    # name: (text, the 1-based line of the first value beyond the bound)
    "position_1e300.obj": (quad(positions=((0, 0, 0), (1e300, 0, 0), (1e300, 1e300, 0), (0, 1, 0))), 2),
    "position_1e200.obj": (quad(positions=((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, -1e200, 0))), 4),
    "uv_1.7e308.obj": (quad(uv=((0, 0), (1.7e308, 0), (1, 1), (0, 1))), 6),
    "uv_1e300.obj": (quad(uv=((0, 0), (1, 0), (1, 1), (0, 1e300))), 8),
    "position_1e76.off": ("OFF\n4 1 0\n0 0 0\n1e76 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n", 4),
    "position_1e300.ply": ("ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
                           "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n1 0 0\n1 1 -1e300\n0 1 0\n4 0 1 2 3\n", 12),
}


def _lint_warnings(scale: float) -> list[str]:
    """The RuntimeWarnings of linting 200 random quads (corners within +-4 ``scale``, uv and normals) with every
    reading and diagonal."""
    from affinity.lint import mesh_report
    from affinity.mesh import mesh_from_polygons

    rng = np.random.default_rng(5)
    positions = rng.uniform(-4, 4, (800, 3)) * scale
    normals = rng.normal(size=(800, 3))
    mesh = mesh_from_polygons("x.obj", positions, np.arange(800).reshape(200, 4), texcoords=rng.normal(size=(800, 2)),
                              normals=normals / np.linalg.norm(normals, axis=1)[:, None])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for measure in ("error", "centre", "barycentric"):
            for diagonal in ("both", "shortest"):
                mesh_report("x.obj", mesh, Settings(measure=measure, diagonal=diagonal))
    return [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]


def test_the_bound_is_where_the_lint_arithmetic_overflows():
    """At the bound the lint's arithmetic is finite; a hundred times above it (positions near 4e77, the squared
    cross products of edges past 1.8e308) it overflows: the bound is the arithmetic's, with its margin."""
    assert _lint_warnings(LARGEST / 4) == []
    assert _lint_warnings(100 * LARGEST / 4)


@pytest.mark.parametrize("name", HUGE)
def test_a_value_beyond_the_bound_is_one_q901_line(tmp_path, name):
    text, line = HUGE[name]
    path = write(tmp_path, name, text)
    done = run("check", str(path))
    assert done.returncode == 2
    assert done.stderr.splitlines() == [
        f"{path}:{line}: Q901 unreadable: value {done.stderr.split('value ')[1].split(' ')[0]} is out of range: "
        "magnitudes above 1e+75 overflow the lint's arithmetic"]
    assert "Warning" not in done.stderr


def test_values_at_the_bound_lint_without_a_warning(tmp_path):
    """Within the bound (positions at -1e75 and 1e75, uv at 1e75) the lint's arithmetic stays finite: no
    RuntimeWarning reaches the user, and the outputs are strict JSON."""
    positions = write(tmp_path, "positions.obj", quad(positions=((0, 0, 0), (1e75, 0, 0), (1e75, 1e75, 0),
                                                                 (-1e75, 1e75, 0))))
    uv = write(tmp_path, "uv.obj", quad(uv=((0, 0), (1e75, 0), (1, 1e75), (0, 1))))
    for fmt in ("json", "sarif"):
        done = subprocess.run([sys.executable, "-W", "error", "-m", "affinity.cli", "check", "--format", fmt,
                               str(positions), str(uv)], capture_output=True, text=True, timeout=300)
        assert done.returncode in (0, 1), done.stderr
        assert done.stderr == ""
        strict_loads(done.stdout)


@pytest.mark.parametrize("fmt", ["json", "sarif"])
def test_every_json_format_is_strict_json_on_bad_and_good_files(tmp_path, fmt):
    paths = [str(write(tmp_path, name, text)) for name, (text, _) in HUGE.items()]
    paths += [str(write(tmp_path, "good.obj", TRAPEZOID)), str(write(tmp_path, "square.obj", SQUARE)),
              str(write(tmp_path, "nan.obj", SQUARE.replace("v 1 0 0", "v nan 0 0")))]
    done = run("check", "--format", fmt, *paths)
    assert done.returncode == 2
    doc = strict_loads(done.stdout)
    assert "Q101" in done.stdout
    if fmt == "json":
        assert sum("error" in entry for entry in doc["files"]) == len(HUGE) + 1


def _non_finite_run() -> CheckRun:
    counts = {"faces": 3, "quads": 3, "triangles": 0, "ngons": 0}
    return CheckRun([FileReport("a.obj", counts=counts, group_names=[""],
                                hits=[hits("Q101", [0, 1, 2], [10, 11, 12], [np.inf, np.nan, 3.5])])], Settings())


@pytest.mark.parametrize("module", [json_output, sarif], ids=["json", "sarif"])
def test_a_non_finite_value_is_written_as_strict_json(module):
    """Should a measure ever give inf or NaN, the writers still write RFC 8259 JSON (the value as null)."""
    out = io.StringIO()
    module.write(_non_finite_run(), out)
    doc = strict_loads(out.getvalue())
    values = ([f["value"] for f in doc["findings"]] if module is json_output
              else [r["properties"]["value"] for r in doc["runs"][0]["results"]])
    assert sorted(values, key=lambda v: (v is not None, v)) == [None, None, 3.5]


def test_merge_writes_strict_json(tmp_path):
    paths = [str(write(tmp_path, "good.obj", TRAPEZOID)), str(write(tmp_path, "huge.obj", HUGE["uv_1e300.obj"][0]))]
    shards = []
    for k in (1, 2):
        done = run("check", "--shard", f"{k}/2", "--format", "json", *paths)
        shards.append(write(tmp_path, f"shard{k}.json", done.stdout))
    for fmt in ("json", "sarif"):
        done = run("merge", "--format", fmt, *map(str, shards))
        assert done.returncode == 2, done.stderr
        strict_loads(done.stdout)


def test_report_keeps_the_good_mesh_beside_one_at_1e300(tmp_path):
    """The page holds the good mesh and one Q901 line for the bad one; its 3-D view's data is strict JSON."""
    good = write(tmp_path, "good.obj", TRAPEZOID)
    bad = write(tmp_path, "bad.obj", HUGE["position_1e300.obj"][0])
    page = tmp_path / "report.html"
    done = run("report", str(bad), str(good), "-o", str(page))
    assert done.returncode == 2, done.stderr
    assert f"{bad}:2: Q901 unreadable: value 1e+300 is out of range" in done.stderr
    assert "Traceback" not in done.stderr and "Warning" not in done.stderr
    html = page.read_text()
    assert "good.obj" in html and "Q901" in html
    scripts = re.findall(r'<script type="application/json"[^>]*>(.*?)</script>', html, re.S)
    assert scripts
    for data in scripts:
        strict_loads(data)


def test_report_on_coordinates_within_the_bound_beyond_float32(tmp_path):
    """Positions at 1e75 (beyond float32, within the bound) and uv at 1e70: a page, no traceback, no warning;
    the view's positions are scaled by a power of two into float32's range."""
    big = write(tmp_path, "big.obj", quad(positions=((0, 0, 0), (1e75, 0, 0), (1e75, 1e75, 0), (0, 1, 0))))
    uv = write(tmp_path, "uv.obj", quad(uv=((0, 0), (1e70, 0), (1, 1), (0, 1))))
    page = tmp_path / "report.html"
    done = subprocess.run([sys.executable, "-W", "error::RuntimeWarning", "-m", "affinity.cli", "report", str(big),
                           str(uv), "-o", str(page)], capture_output=True, text=True, timeout=300)
    assert done.returncode in (0, 1), done.stderr
    assert "Warning" not in done.stderr and "Traceback" not in done.stderr
    for data in re.findall(r'<script type="application/json"[^>]*>(.*?)</script>', page.read_text(), re.S):
        strict_loads(data)


def test_texture_lookup_far_outside_int64_wraps_without_a_warning():
    """uv of 1e70 on a 4x4 texture: the texel index is a multiple of 4 beyond int64 (float64 holds it
    exactly), so repeat wrapping reads texel column 0 -- as fmod of the exact value says."""
    from affinity.textures.filtering import _wrapped_texels

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        wrapped = _wrapped_texels(np.array([1e70, -1e70, 5.0]), 4)
    assert wrapped.tolist() == [int(1e70) % 4, int(-1e70) % 4, 1]
