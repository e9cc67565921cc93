"""--measure / ``measure =``: error (default), centre, barycentric; ``misplacement`` as a deprecated alias."""

from __future__ import annotations

import json

import numpy as np
from helpers.cli import TRAPEZOID, run, write

#: The trapezoid (side ratio 1/2) with the unit-square uv at 1024 texels: the split's largest
#: error (1 - r) / (1 + sqrt r)^2 and its shift at the centre (1 - r) / 4, in texels.
ERROR, CENTRE = 1024 * 0.5 / (1 + np.sqrt(0.5)) ** 2, 1024 * 0.125


def findings(result):
    assert result.returncode == 1, result.stdout + result.stderr
    return [f for f in json.loads(result.stdout)["findings"] if f["code"] == "Q101"]


def test_every_affinity_finding_says_its_measure(tmp_path):
    mesh = str(write(tmp_path, "t.obj", TRAPEZOID))
    for flags, measure, value in [((), "error", ERROR), (("--measure", "centre"), "centre", CENTRE),
                                  (("--measure", "barycentric"), "barycentric", np.sqrt(2))]:
        (found,) = findings(run("check", "--format", "json", "--isolated", "--fail-on", "warning", *flags, mesh))
        assert found["measure"] == measure
        # no visibility threshold separates visible creases in the paper's score: its findings stay warnings
        assert found["level"] == ("warning" if measure == "barycentric" else "error")
        assert abs(found["value"] - value) < 1e-4 * value


def test_misplacement_is_error_with_one_warning_on_the_command_line(tmp_path):
    mesh = str(write(tmp_path, "t.obj", TRAPEZOID))
    result = run("check", "--format", "json", "--isolated", "--measure", "misplacement", mesh)
    (found,) = findings(result)
    assert found["measure"] == "error" and abs(found["value"] - ERROR) < 1e-3
    warnings = [line for line in result.stderr.splitlines() if "deprecated" in line]
    assert len(warnings) == 1 and "misplacement" in warnings[0] and "error" in warnings[0]


def test_misplacement_is_error_with_one_warning_in_a_config_file(tmp_path):
    write(tmp_path, "affinity.toml", 'measure = "misplacement"\n')
    mesh = str(write(tmp_path, "t.obj", TRAPEZOID))
    result = run("check", "--format", "json", mesh, cwd=tmp_path)
    (found,) = findings(result)
    assert found["measure"] == "error"
    warnings = [line for line in result.stderr.splitlines() if "deprecated" in line]
    assert len(warnings) == 1 and "affinity.toml" in warnings[0]


def test_an_unknown_measure_is_a_usage_error(tmp_path):
    result = run("check", "--measure", "nonsense", str(write(tmp_path, "t.obj", TRAPEZOID)))
    assert result.returncode == 2 and "nonsense" in result.stderr and "Traceback" not in result.stderr
