"""A run that is killed leaves nothing behind (issue 47): no worker process, no temporary output file.

Linux only: the processes of a run are found in /proc (their parent's pid).
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytestmark = [pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds processes in /proc (Linux)"),
              pytest.mark.slow]  # signals sent to running processes, and waits for them

#: Quads a side of the test mesh: 90,000 disaffine quads, a 7 MB JSON output that takes a second or more.
SIDE = 300


def write_grid(path: Path, side: int = SIDE, seed: int = 0) -> None:
    """A ``side`` x ``side`` grid of quads with jittered positions and regular uv: every quad disaffine."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0 : side + 1, 0 : side + 1].astype(float)
    positions = np.column_stack([(x + rng.uniform(-0.3, 0.3, x.shape)).ravel(),
                                 (y + rng.uniform(-0.3, 0.3, y.shape)).ravel()])
    corner = (np.arange(side)[:, None] * (side + 1) + np.arange(side)[None, :]).ravel() + 1
    faces = np.column_stack([corner, corner + 1, corner + side + 2, corner + side + 1])
    lines = [f"v {px:.4f} {py:.4f} 0" for px, py in positions]
    lines += [f"vt {u:.4f} {v:.4f}" for u, v in np.column_stack([x.ravel(), y.ravel()]) / side]
    lines += ["f " + " ".join(f"{k}/{k}" for k in face) for face in faces.tolist()]
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def big_meshes(tmp_path_factory) -> Path:
    """Sixteen copies of the grid (copies, not links: a file under two names is checked once): work for two
    workers for a few seconds (a 90,000-quad grid takes some 0.1 s to check)."""
    folder = tmp_path_factory.mktemp("big")
    write_grid(folder / "grid0.obj")
    for copy in range(1, 16):
        shutil.copyfile(folder / "grid0.obj", folder / f"grid{copy}.obj")
    return folder


def start(*args: str, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "affinity.cli", *args], cwd=cwd,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def children(pid: int) -> list[int]:
    """The live processes whose parent is ``pid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            fields = state_and_parent(int(entry.name))
            if fields is not None and fields[1] == pid and fields[0] != "Z":
                found.append(int(entry.name))
    return found


def state_and_parent(pid: int) -> tuple[str, int] | None:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    state, parent = stat.rsplit(")", 1)[1].split()[:2]
    return state, int(parent)


def alive(pid: int) -> bool:
    """Running (a zombie waiting for init to reap it is not)."""
    fields = state_and_parent(pid)
    return fields is not None and fields[0] != "Z"


def wait_for(condition, timeout: float) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.01)
    return condition()


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
