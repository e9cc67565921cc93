"""``benchmarks/bench_check.py --small``: the table the docs quote is written where the convention says."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # a benchmark run

ROOT = Path(__file__).resolve().parents[1]


def test_the_small_case_writes_the_table_with_both_times_and_their_ratio(tmp_path):
    done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "bench_check.py"), "--small", "--out",
                           str(tmp_path)], capture_output=True, text=True, timeout=300, cwd=ROOT / "benchmarks")
    assert done.returncode == 0, done.stderr
    table = (tmp_path / "bench_check.md").read_text()
    assert table == done.stdout
    assert "2,000 quads" in table and "Load average before:" in table
    row = re.search(r"^\| affinity check --no-cache --format json \| ([\d.]+) \| ([\d.]+) \| [\d.]+ \| (\d+) \|$",
                    table, re.MULTILINE)
    assert row and 0 < float(row[1]) <= float(row[2]) and int(row[3]) > 0
    if importlib.util.find_spec("pyvista") is not None:  # the reference case runs only where pyvista is
        reference = re.search(r"^\| pyvista\.read \| [\d.]+ \| ([\d.]+) \|", table, re.MULTILINE)
        ratio = re.search(r"\(medians\): ([\d.]+) \(goal: at most 0\.5\)", table)
        assert reference and ratio
        # the printed medians are rounded to 0.01 s
        assert abs(float(ratio[1]) - float(row[2]) / float(reference[1])) < 0.01 + 0.01 / float(reference[1])
    assert (tmp_path / "bench_check.json").exists()
