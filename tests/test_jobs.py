"""Batch runs and start-up: ``--jobs`` keeps the output stable; ``affinity check`` imports nothing heavy."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.cli import run, run_process
from helpers.quads import SQUARE, UNIT_UV, quad_obj, trapezoid

from affinity.pipeline.check import BYTES_PER_WORKER, auto_jobs, available_cpus, check_files
from affinity.settings import Settings

HEAVY = ("render", "PIL", "matplotlib", "jinja2", "trimesh", "igl", "pyvista", "tqdm")


@pytest.fixture
def directory(tmp_path: Path) -> Path:
    """Twelve files of different sizes (so workers finish out of order), one unreadable."""
    for i in range(12):
        quads = [(trapezoid(0.2 + 0.1 * k, 3 * k), UNIT_UV) for k in range(1 + 40 * (i % 4))]
        quads += [(SQUARE, UNIT_UV)] * i
        (tmp_path / f"mesh_{i:02d}.obj").write_text(quad_obj(quads))
    (tmp_path / "mesh_05.obj").write_text("v 0 0 0\nf 1 2 3\n")
    return tmp_path


@pytest.mark.parametrize("fmt", ["text", "json", "sarif"])
def test_two_jobs_give_the_same_output_as_one(directory, fmt):
    one = run("check", "--jobs", "1", "--format", fmt, "--verbose" if fmt == "text" else "--quiet", ".",
              cwd=directory)
    two = run_process("check", "--jobs", "2", "--format", fmt, "--verbose" if fmt == "text" else "--quiet", ".",
                      cwd=directory)  # worker processes: the boundary itself
    assert one.returncode == two.returncode == 2, one.stderr
    assert one.stdout == two.stdout and one.stderr == two.stderr
    assert one.stdout.count("Q101") > 100


def test_reports_come_back_in_task_order(directory):
    tasks = [(str(p), Settings()) for p in sorted(directory.glob("*.obj"), reverse=True)]
    reports = check_files(tasks, jobs=3)
    assert [r.path for r in reports] == [path for path, _ in tasks]
    assert [r.n_findings for r in reports] == [r.n_findings for r in check_files(tasks, jobs=1)]


def test_progress_wraps_the_report_stream(directory):
    seen = []

    def progress(reports, total):
        seen.append(total)
        yield from reports

    tasks = [(str(p), Settings()) for p in sorted(directory.glob("*.obj"))[:3]]
    assert len(check_files(tasks, jobs=2, progress=progress)) == 3 and seen == [3]


def test_automatic_jobs_use_every_cpu_only_for_enough_data(tmp_path):
    small, big = tmp_path / "small.obj", tmp_path / "big.obj"
    small.write_text(quad_obj([(SQUARE, UNIT_UV)]))
    big.write_bytes(b"#" * (4 * BYTES_PER_WORKER))
    assert 1 <= available_cpus() <= (os.cpu_count() or 1)
    assert auto_jobs([str(small)] * 8) == 1
    assert auto_jobs([str(big), str(small)]) == min(available_cpus(), 5)


def test_bad_jobs_value_is_a_usage_error(tmp_path):
    result = run("check", "--jobs", "0", str(tmp_path))
    assert result.returncode == 2 and "--jobs" in result.stderr


def test_check_imports_nothing_heavy(tmp_path):
    mesh = tmp_path / "bad.obj"
    mesh.write_text(quad_obj([(trapezoid(), UNIT_UV)]))
    probe = (
        "import sys, runpy\n"
        "sys.argv = ['affinity', 'check', sys.argv[1]]\n"
        "try:\n"
        "    runpy.run_module('affinity.cli', run_name='__main__')\n"
        "except SystemExit as done:\n"
        "    print('EXIT', done.code)\n"
        "print('MODULES', ' '.join(sorted(sys.modules)))\n"
    )
    result = subprocess.run([sys.executable, "-c", probe, str(mesh)], capture_output=True, text=True, timeout=120)
    assert "EXIT 1" in result.stdout, result.stdout + result.stderr
    modules = result.stdout.split("MODULES ", 1)[1].split()
    heavy = sorted(m for m in modules if m.split(".")[0] in HEAVY)
    assert heavy == []
    assert "numpy" in modules  # the probe really ran the check
