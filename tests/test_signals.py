"""A run that is killed leaves nothing behind (issue 47): no worker process, no temporary output file.

Linux only: the processes of a run are found in /proc (their parent's pid).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.processes import alive, children, start, wait_for

pytestmark = [pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds processes in /proc (Linux)"),
              pytest.mark.slow]  # signals sent to running processes, and waits for them

def temporaries(folder: Path) -> list[str]:
    return sorted(name for name in os.listdir(folder) if name.endswith(".tmp"))


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_no_process_of_a_two_job_run_outlives_a_signal(big_meshes, tmp_path, signum):
    run = start("check", "--no-cache", "-j", "2", "--format", "json", "-o", str(tmp_path / "out.json"), ".",
                cwd=big_meshes)
    try:
        assert wait_for(lambda: len(children(run.pid)) == 2, 60), "the two workers never started"
        workers = children(run.pid)
        time.sleep(0.05)  # both inside a check
        assert all(map(alive, workers)) and not temporaries(tmp_path)  # still checking
        os.kill(run.pid, signum)
        run.wait(timeout=5)
        assert wait_for(lambda: not any(map(alive, workers)), 5), "a worker outlived its parent by 5 s"
    finally:
        run.kill()
        run.wait()
    assert run.returncode == (-signum if signum == signal.SIGKILL else 128 + signum)
    assert "Traceback" not in run.stderr.read()
    assert temporaries(tmp_path) == [] and not (tmp_path / "out.json").exists()


def signal_while_writing(out: Path, signum: int, cwd: Path) -> subprocess.Popen:
    """``check -o OUT`` of the 90,000-quad grid, sent ``signum`` once its temporary file exists; finished."""
    run = start("check", "--no-cache", "--format", "json", "-o", str(out), "grid0.obj", cwd=cwd)
    try:
        assert wait_for(lambda: temporaries(out.parent), 60), "the output was never written"
        os.kill(run.pid, signum)
        run.wait(timeout=5)
    finally:
        run.kill()
        run.wait()
    return run


def test_sigterm_while_writing_the_output_removes_the_temporary_file(big_meshes, tmp_path):
    out = tmp_path / "out.json"
    out.write_text("the previous result\n")
    run = signal_while_writing(out, signal.SIGTERM, big_meshes)
    assert run.returncode == 128 + signal.SIGTERM and "Traceback" not in run.stderr.read()
    assert temporaries(tmp_path) == [] and out.read_text() == "the previous result\n"


def test_the_next_write_removes_a_temporary_file_left_by_a_killed_run(big_meshes, tmp_path):
    out = tmp_path / "out.json"
    run = signal_while_writing(out, signal.SIGKILL, big_meshes)
    [stale] = temporaries(tmp_path)
    assert stale.startswith(f".out.json.{run.pid}-")
    mine = tmp_path / f".out.json.{os.getpid()}-live.tmp"  # a writer still running: this test
    foreign = tmp_path / ".out.json.notes.tmp"  # not a name this tool writes
    mine.write_text("")
    foreign.write_text("")
    (tmp_path / "small.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    done = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--no-cache", "-o", str(out), "small.obj"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert temporaries(tmp_path) == sorted([mine.name, foreign.name]) and out.is_file()
