"""A lost ``-j`` worker (issue 53): its files are retried once in a fresh worker, then reported as Q901
"worker died"; the run goes on and exits 2 with every other file's result. SIGTERM to ``check -j 2`` leaves
no process of the run alive 5 s later, whenever it lands (20 trials).

A worker is killed the way the kernel's OOM killer or a crash in native code ends it: SIGKILL to itself,
from a check replaced (in this process, inherited by the forked workers; in the CLI, by a ``sitecustomize``
module on the path) with one that dies on the file named ``die.obj``.

Linux only: the processes of a run are found in /proc.
"""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.cli import SQUARE, TRAPEZOID, write
from helpers.processes import alive, children, start, wait_for

from affinity.pipeline import check as pipeline_check
from affinity.pipeline.check import WORKER_DIED, check_files
from affinity.settings import Settings

pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds processes in /proc (Linux)")

#: A check that kills its own process on ``die.obj`` (every time, or only while ``once`` does not exist yet).
KILLER = '''
import os, signal
from affinity.pipeline import check as _check
_real = _check.check_file

def check_file(path, settings, usd=None, source=None, _once={once!r}):
    if os.path.basename(path) == "die.obj" and (_once is None or not os.path.exists(_once)):
        if _once is not None:
            open(_once, "w").close()
        os.kill(os.getpid(), signal.SIGKILL)
    return _real(path, settings, usd, source)

_check.check_file = check_file
'''


def folder_of_meshes(tmp_path: Path) -> list[str]:
    names = [f"m{k}.obj" for k in range(6)]
    paths = [str(write(tmp_path, name, TRAPEZOID if k % 2 else SQUARE)) for k, name in enumerate(names)]
    return [*paths[:3], str(write(tmp_path, "die.obj", TRAPEZOID)), *paths[3:]]


def killing(monkeypatch, once: Path | None) -> None:
    """Run :data:`KILLER` here (it replaces ``check_file``); the real one is put back after the test."""
    monkeypatch.setattr(pipeline_check, "check_file", pipeline_check.check_file)
    exec(KILLER.format(once=None if once is None else str(once)), {})


def test_a_file_that_kills_every_worker_is_q901_and_the_others_are_checked(tmp_path, monkeypatch):
    paths = folder_of_meshes(tmp_path)
    tasks = [(path, Settings()) for path in paths]
    expected = check_files([t for t in tasks if not t[0].endswith("die.obj")], jobs=1)
    killing(monkeypatch, None)
    reports = check_files(tasks, jobs=2)
    assert [r.path for r in reports] == paths
    died = reports[3]
    assert died.error == WORKER_DIED and died.transient
    others = reports[:3] + reports[4:]
    assert [r.error for r in others] == [None] * 6
    assert [[(h.code, h.faces.tolist()) for h in r.hits] for r in others] == [
        [(h.code, h.faces.tolist()) for h in r.hits] for r in expected]


def test_a_worker_killed_once_is_retried_and_its_file_checked(tmp_path, monkeypatch):
    paths = folder_of_meshes(tmp_path)
    killing(monkeypatch, tmp_path / "killed-once")
    reports = check_files([(path, Settings()) for path in paths], jobs=2)
    assert (tmp_path / "killed-once").exists()  # it did die once
    assert [r.error for r in reports] == [None] * 7
    assert [h.code for h in reports[3].hits] == ["Q101"]


def test_check_j2_with_a_dying_worker_exits_2_with_every_other_file(tmp_path):
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(KILLER.format(once=None))
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    paths = folder_of_meshes(meshes)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--no-cache", "-j", "2", "--format", "json",
                           *paths], capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 2
    assert done.stderr.splitlines() == [f"{meshes / 'die.obj'}:0: Q901 unreadable: {WORKER_DIED}"]
    doc = json.loads(done.stdout)
    assert [entry["path"] for entry in doc["files"]] == paths
    assert [("error" in entry) for entry in doc["files"]] == [False] * 3 + [True] + [False] * 3
    assert {f["path"] for f in doc["findings"]} == {p for p in paths if Path(p).name in ("m1.obj", "m3.obj", "m5.obj")}


@pytest.mark.slow
def test_sigterm_to_check_j2_leaves_no_process_in_20_trials(big_meshes, tmp_path):
    """SIGTERM at 20 moments of a ``check -j 2`` run (while the workers check, and while they send their
    results): the run and both workers are gone 5 s later, every time."""
    rng = random.Random(53)
    hung = [trial for trial in range(20) if not _gone_after_sigterm(big_meshes, tmp_path / f"out{trial}.json",
                                                                     rng.uniform(0.0, 1.5))]
    assert hung == []


def _gone_after_sigterm(folder: Path, out: Path, delay: float) -> bool:
    """Whether ``check -j 2`` of ``folder``, sent SIGTERM ``delay`` s after its workers started, and both
    workers are gone 5 s later (and it printed no traceback)."""
    run = start("check", "--no-cache", "-j", "2", "--format", "json", "-o", str(out), ".", cwd=folder)
    try:
        assert wait_for(lambda: len(children(run.pid)) == 2, 60), "the two workers never started"
        workers = children(run.pid)
        time.sleep(delay)
        os.kill(run.pid, signal.SIGTERM)
        gone = wait_for(lambda: not alive(run.pid) and not any(map(alive, workers)), 5)
    finally:
        run.kill()
        run.wait()
    assert "Traceback" not in run.stderr.read()
    return gone
