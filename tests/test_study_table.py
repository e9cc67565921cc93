"""One study table: package data, written by ``affinity bench --table``, read by the demo report."""

from __future__ import annotations

import csv
import subprocess
from pathlib import Path
from types import SimpleNamespace

from helpers.cli import TRAPEZOID, run, write

import affinity
from affinity.report.sections import STUDY_RESULTS, study_section
from affinity.study.run import PACKAGE_TABLE, SUMMARY_NAME
from affinity.study.sweep import COLUMNS

ROOT = Path(__file__).resolve().parents[1]
IN_PACKAGE = Path(affinity.__file__).parent / "data" / "study" / "study.csv"


def test_the_demo_report_reads_the_package_table():
    assert STUDY_RESULTS == IN_PACKAGE == Path(PACKAGE_TABLE)
    with open(IN_PACKAGE, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    figures = {row["scene"] for row in rows if not row["scene"].endswith(".obj")}
    section = study_section(SimpleNamespace(demo=True))
    assert section.data["scenes"] == len(figures) > 0
    assert section.data["repeats"] == min(int(row["repeats"]) for row in rows)
    assert section.data["svg"].count("<svg") >= 1


def test_the_repository_holds_one_study_table():
    listed = subprocess.run(["git", "ls-files", "*study.csv"], cwd=ROOT, capture_output=True, text=True,
                            check=True).stdout.split()
    assert listed == ["affinity/data/study/study.csv"]
    summary = (ROOT / "reports" / "study" / SUMMARY_NAME).read_text(encoding="utf-8")
    assert "[study.csv](../../affinity/data/study/study.csv)" in summary


def test_bench_writes_its_table_where_told_and_the_summary_links_to_it(tmp_path):
    mesh = write(tmp_path, "trap.obj", TRAPEZOID)
    out, table = tmp_path / "out", tmp_path / "table" / "study.csv"
    table.parent.mkdir()
    done = run("bench", str(mesh), "--size", "40x30", "--repeat", "1", "-q", "-o", str(out), "--table", str(table))
    assert done.returncode == 0, done.stderr
    assert not (out / "study.csv").exists()
    with open(table, newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames) == COLUMNS
        assert {row["scene"] for row in reader} == {"trap.obj"}
    summary = (out / SUMMARY_NAME).read_text(encoding="utf-8")
    assert "All rows: [study.csv](../table/study.csv)." in summary
    assert f"--table {table}" in summary  # the command as it could be typed again
