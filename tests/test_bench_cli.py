"""`affinity bench` as CI runs it: --quick into a folder, then the CSV, summary and charts are read back."""

import csv
import math

import pytest
from helpers.cli import run

from affinity.study.run import CHART_NAMES, CSV_NAME, SUMMARY_NAME
from affinity.study.sweep import COLUMNS, PLAIN_METHODS

pytestmark = pytest.mark.slow  # a benchmark run


def bench(*args):
    return run("bench", *args)


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bench") / "out"
    return bench("--quick", "-o", str(folder)), folder


def test_quick_bench_writes_a_csv_of_every_measurement(quick):
    result, folder = quick
    assert result.returncode == 0, result.stderr
    with open(folder / CSV_NAME, newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames) == COLUMNS
        rows = list(reader)
    scenes = {row["scene"] for row in rows}
    assert scenes == {"trapezoid front", "sphere 8x16", "quad strip"}
    for scene in scenes:
        methods = [row["method"] for row in rows if row["scene"] == scene]
        assert set(PLAIN_METHODS) <= set(methods) and methods.count("hybrid") == 3  # the quick tolerances
    for row in rows:
        assert float(row["seconds"]) > 0 and int(row["fragments"]) > 0
        assert float(row["seconds_min"]) <= float(row["seconds"]) <= float(row["seconds_max"])
        assert 0 <= float(row["to_mvc"]) <= 1 and row["pareto"] in ("True", "False")
        assert math.isfinite(float(row["err_rms"])) and float(row["err_rms"]) >= 0
    exact = [row for row in rows if row["method"] == "exact"]
    assert all(float(row["err_max"]) == 0 and row["psnr_db"] == "inf" for row in exact)


def test_quick_bench_writes_the_summary_and_charts(quick):
    from PIL import Image

    result, folder = quick
    assert result.returncode == 0, result.stderr
    summary = (folder / SUMMARY_NAME).read_text(encoding="utf-8")
    assert summary.startswith("# Error against run time")
    assert "## Where the hybrid sits" in summary and "### quad strip" in summary
    header = next(line for line in summary.splitlines() if line.startswith("| scene |"))
    table = summary.splitlines()[summary.splitlines().index(header) + 2:][:3]
    assert [line.split("|")[1].strip() for line in table] == ["trapezoid front", "sphere 8x16", "quad strip"]
    assert "numpy" in summary and "cpu" in summary
    for name in CHART_NAMES:
        with Image.open(folder / name) as image:
            assert image.format == "PNG" and min(image.size) > 200


def test_bench_without_anything_to_study_is_a_usage_error(tmp_path):
    result = bench(str(tmp_path / "missing.obj"), "-o", str(tmp_path / "out"))
    assert result.returncode == 2
    assert "missing.obj" in result.stderr and "Traceback" not in result.stderr
    result = bench("--quick", "--repeat", "0", "-o", str(tmp_path / "out"))
    assert result.returncode == 2 and "--repeat" in result.stderr
