"""``affinity check --scheduler``: a real LocalCluster (2 worker processes on 127.0.0.1) gives a local run's output."""

from __future__ import annotations

import argparse
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from contextlib import nullcontext
from pathlib import Path

import pytest
from helpers.cli import run
from helpers.quads import SQUARE, UNIT_UV, quad_obj, trapezoid

from affinity.pipeline import cluster as cluster_module
from affinity.pipeline.check import check_file, check_files
from affinity.settings import Settings

pytest.importorskip("distributed")
pytestmark = pytest.mark.slow  # a Dask cluster of worker processes


@pytest.fixture(scope="module")
def client():
    """One cluster for the module, started the way ``--scheduler local:2`` starts it."""
    with cluster_module.connect("local:2") as dask_client:
        assert len(dask_client.scheduler_info()["workers"]) == 2
        assert dask_client.scheduler.address.startswith("tcp://127.0.0.1:")
        yield dask_client


@pytest.fixture(scope="module")
def assets(tmp_path_factory) -> Path:
    """Meshes of different sizes with known findings, a clean one, a broken one and one in a subfolder."""
    folder = tmp_path_factory.mktemp("assets")
    for i in range(10):
        quads = [(trapezoid(0.2 + 0.1 * k, 3 * k), UNIT_UV) for k in range(1 + 30 * (i % 3))]
        (folder / f"mesh_{i:02d}.obj").write_text(quad_obj(quads + [(SQUARE, UNIT_UV)] * (400 * i)))
    (folder / "clean.obj").write_text(quad_obj([(SQUARE, UNIT_UV)]))
    (folder / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    (folder / "props").mkdir()
    (folder / "props" / "lid.obj").write_text(quad_obj([(trapezoid(0.5), UNIT_UV)]))
    return folder


def check(folder: Path, *extra: str, env: dict | None = None) -> subprocess.CompletedProcess:
    """``affinity check --no-cache ... .`` in ``folder``; the local runs are remembered (they do not change)."""
    key = (folder, extra, tuple(sorted((env or {}).items())))
    if "--scheduler" not in extra and key in _LOCAL_RUNS:
        return _LOCAL_RUNS[key]
    result = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--no-cache", *extra, "."],
                          capture_output=True, text=True, cwd=folder, timeout=120, env={**os.environ, **(env or {})})
    if "--scheduler" not in extra:
        _LOCAL_RUNS[key] = result
    return result


_LOCAL_RUNS: dict = {}


@pytest.mark.parametrize("fmt", ["text", "json"])
def test_cluster_output_is_the_local_output(client, assets, fmt):
    local = check(assets, "--verbose", "--format", fmt)
    remote = check(assets, "--verbose", "--format", fmt, "--scheduler", client.scheduler.address)
    assert local.returncode == remote.returncode == 2, local.stderr
    assert (remote.stdout, remote.stderr) == (local.stdout, local.stderr)
    assert "broken.obj:3: Q901 unreadable" in local.stderr and local.stdout.count("Q101") > 30


def test_scheduler_from_the_environment_and_from_the_config(client, assets, tmp_path):
    local = check(assets, "--verbose", "--format", "text")
    address = {"DASK_SCHEDULER_ADDRESS": client.scheduler.address}
    assert check(assets, "--verbose", "--format", "text", "--scheduler", "env", env=address).stdout == local.stdout
    (tmp_path / "affinity.toml").write_text('scheduler = "tcp://127.0.0.1:1"\n')
    configured = subprocess.run(
        [sys.executable, "-m", "affinity.cli", "check", "--no-cache", str(assets)], capture_output=True, text=True,
        cwd=tmp_path, timeout=120, env={**os.environ, "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "1s"})
    assert configured.returncode == 2 and "--scheduler tcp://127.0.0.1:1: no Dask scheduler" in configured.stderr


def test_a_lost_worker_costs_only_its_tasks(client, assets):
    """A worker killed mid-batch: the scheduler reruns its batch, and every file's result is the local run's."""
    from affinity.shards.journal import json_of

    tasks = [(str(p), Settings()) for p in sorted(assets.rglob("*.obj"))]
    expected = [json_of(r, Settings()) for r in check_files(tasks, jobs=1)]
    seen, killed = [], []

    def kill_a_busy_worker(results, total):
        for index, report in results:
            if not seen:  # the first file is back: the others are still queued or running on the workers
                busy = [w for w, keys in client.processing().items() if keys]
                killed.append(client.run(os.getpid, workers=busy[:1])[busy[0]])
                os.kill(killed[0], signal.SIGKILL)
            seen.append(index)
            yield index, report

    reports = check_files(tasks, progress=kill_a_busy_worker, cluster=lambda: nullcontext(client))
    assert sorted(seen) == list(range(len(tasks)))
    assert [json_of(r, Settings()) for r in reports] == expected
    assert not any((r.error or "").startswith("internal error") for r in reports)
    client.wait_for_workers(2, timeout=60)
    assert killed[0] not in client.run(os.getpid).values()  # the nanny started a new worker process


def test_files_go_to_the_cluster_in_batches(client, assets):
    """12 files on 2 workers: fewer tasks than files, at least a few per worker, each file in one."""
    tasks = [(str(p), Settings()) for p in sorted(assets.rglob("*.obj"))]
    planned = cluster_module.batches([os.path.getsize(p) for p, _ in tasks], workers=2)
    assert len(tasks) > len(planned) >= 2 * 2
    assert sorted(i for batch in planned for i in batch) == list(range(len(tasks)))
    submitted = []
    original = client.submit

    def counting(*args, **kwargs):
        submitted.append(kwargs["key"])
        return original(*args, **kwargs)

    client.submit = counting
    try:
        results = dict(cluster_module.check_on_cluster(client, tasks, check_file))
    finally:
        del client.submit
    assert len(submitted) == len(planned) and sorted(results) == list(range(len(tasks)))


def test_a_path_the_worker_cannot_see_is_unreadable_with_the_reason(client, tmp_path):
    missing = tmp_path / "only-on-the-client" / "crate.obj"
    [(index, report)] = list(cluster_module.check_on_cluster(client, [(str(missing), Settings())], check_file))
    assert index == 0 and report.path == str(missing)
    assert "not found on the Dask worker" in report.error and "shared storage" in report.error
    assert report.transient  # a mount problem, not the file's result: never cached


def test_a_worker_that_cannot_see_the_file_leaves_no_cache_entry(tmp_path):
    """The client hashes the file, the worker reports it unseen: the next run (mount fixed) checks it."""
    from affinity.findings import FileReport
    from affinity.pipeline.cache import ResultCache

    mesh = tmp_path / "crate.obj"
    mesh.write_text(quad_obj([(trapezoid(0.5), UNIT_UV)]))
    cache = ResultCache(str(tmp_path / "cache"), tool="t")
    key = cache.key(str(mesh), Settings())
    unseen = cluster_module._check_on_worker(check_file, str(tmp_path / "elsewhere.obj"), str(mesh), Settings(), None)
    cache.put(key, unseen)
    assert cache.get(key) is None
    cache.put(key, FileReport(str(mesh), counts={"faces": 1}))
    assert cache.get(key) is not None  # a real result under the same key is kept
    cache.close()


def test_cached_files_are_not_submitted(client, assets, tmp_path, monkeypatch, an_hour_later):
    from affinity.pipeline.cache import ResultCache

    tasks = [(str(p), Settings()) for p in sorted(assets.glob("mesh_*.obj"))]
    submitted = []
    real = cluster_module.check_on_cluster

    def counting(dask_client, todo, check, usd=None):
        submitted.append(len(todo))
        return real(dask_client, todo, check, usd)

    monkeypatch.setattr(cluster_module, "check_on_cluster", counting)
    runs, connections = [], []

    def reach_the_cluster():
        connections.append(1)
        return nullcontext(client)

    for _ in range(2):
        cache = ResultCache(str(tmp_path), tool="t")
        runs.append([r.n_findings for r in check_files(tasks, cache=cache, cluster=reach_the_cluster)])
        cache.close()
    assert submitted == [len(tasks)] and connections == [1] and runs[0] == runs[1]


def test_a_file_swapped_while_the_cluster_checks_it_is_not_stored(client, tmp_path, monkeypatch):
    """The client hashes the file for its key, a worker reads it after a swap; restored, the cached run
    must equal a fresh one (issue 47)."""
    from affinity.pipeline.cache import ResultCache

    mesh = tmp_path / "mesh.obj"
    affine, disaffine = quad_obj([(SQUARE, UNIT_UV)]), quad_obj([(trapezoid(0.5), UNIT_UV)])
    mesh.write_text(affine)
    tasks = [(str(mesh), Settings())]
    key = ResultCache.key

    def key_then_swap(self, path, *args, **kwargs):
        found = key(self, path, *args, **kwargs)
        mesh.write_text(disaffine)
        return found

    def cached_run() -> list[int]:
        cache = ResultCache(str(tmp_path / "cache"), tool="t")
        try:
            return [r.n_findings for r in check_files(tasks, cache=cache, cluster=lambda: nullcontext(client))]
        finally:
            cache.close()

    monkeypatch.setattr(ResultCache, "key", key_then_swap)
    assert cached_run() == [1]  # the worker read the swapped file
    monkeypatch.undo()
    mesh.write_text(affine)
    assert cached_run() == [r.n_findings for r in check_files(tasks, jobs=1)] == [0]


def dead_address() -> str:
    """A scheduler address nothing listens on."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return f"tcp://127.0.0.1:{probe.getsockname()[1]}"


def test_a_scheduler_that_does_not_answer_is_one_line_and_exit_2(assets):
    address = dead_address()
    port = address.rsplit(":", 1)[1]
    result = check(assets, "--scheduler", address,
                   env={"DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "1s"})
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.strip().count("\n") == 0 and "Traceback" not in result.stderr
    assert f"tcp://127.0.0.1:{port}: no Dask scheduler answered within 1 s" in result.stderr


@pytest.mark.parametrize("spec, message", [("env", "DASK_SCHEDULER_ADDRESS is not set"),
                                           ("local:0", "expected local:N")])
def test_bad_scheduler_specs_are_usage_errors(assets, spec, message):
    env = {k: v for k, v in os.environ.items() if k != "DASK_SCHEDULER_ADDRESS"}
    result = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--scheduler", spec, "."],
                            capture_output=True, text=True, cwd=assets, timeout=120, env=env)
    assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr


def test_check_without_scheduler_never_imports_dask(assets):
    probe = (
        "import sys, runpy\n"
        "sys.argv = ['affinity', 'check', sys.argv[1]]\n"
        "try:\n"
        "    runpy.run_module('affinity.cli', run_name='__main__')\n"
        "except SystemExit:\n"
        "    pass\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))\n"
    )
    env = {**os.environ, "DASK_SCHEDULER_ADDRESS": "tcp://127.0.0.1:1"}  # the variable alone changes nothing
    result = subprocess.run([sys.executable, "-c", probe, str(assets / "clean.obj")],
                            capture_output=True, text=True, env=env, timeout=120)
    assert result.stdout.strip().endswith("[]"), result.stdout + result.stderr
    assert run("check", str(assets / "clean.obj")).returncode == 0


def test_the_progress_bar_passes_every_result_through():
    import io

    from affinity.findings import FileReport
    from affinity.pipeline.progress import bar

    results = [(2, FileReport("a.obj")), (0, FileReport("b.obj")), (1, FileReport("c.obj", error="x"))]
    assert list(bar(iter(results), 3, io.StringIO())) == results


def test_with_every_file_cached_the_scheduler_is_not_reached(assets, tmp_path):
    """The client consults the cache first: nothing to submit, no connection (a dead address passes)."""
    library = tmp_path / "library"
    library.mkdir()
    for source in sorted(assets.glob("mesh_0[0-4].obj")):
        target = library / source.name
        target.write_bytes(source.read_bytes())
        old = time.time() - 3600  # out of the racy window, so the pre-keys are kept
        os.utime(target, (old, old))
    env = {**os.environ, "AFFINITY_CACHE_DIR": str(tmp_path / "cache"),
           "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "1s"}

    def cached_check(*extra):
        return subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--verbose", *extra, "."],
                              capture_output=True, text=True, cwd=library, timeout=120, env=env)

    first = cached_check()
    again = cached_check("--scheduler", dead_address(), "--jobs", "2")
    assert first.returncode == again.returncode == 1 and first.stdout.count("Q101") > 30
    assert again.stdout == first.stdout
    assert again.stderr == ("affinity: warning: --jobs 2 is ignored with --scheduler: "
                            "the cluster's workers check the files\n")
    (library / "mesh_00.obj").write_text(quad_obj([(SQUARE, UNIT_UV)]))  # one file to check: now it connects
    changed = cached_check("--scheduler", dead_address())
    assert changed.returncode == 2 and "no Dask scheduler answered within 1 s" in changed.stderr


def test_scheduler_none_checks_here_whatever_the_config_says(assets, tmp_path):
    (tmp_path / "affinity.toml").write_text(f'scheduler = "{dead_address()}"\n')
    here = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--no-cache", "--verbose",
                           "--scheduler", "none", str(assets)], capture_output=True, text=True, cwd=tmp_path,
                          timeout=120)
    local = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--no-cache", "--verbose", "--isolated",
                            str(assets)], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert here.returncode == local.returncode == 2 and (here.stdout, here.stderr) == (local.stdout, local.stderr)
    assert here.stdout.count("Q101") > 30


def test_the_dashboard_link_is_said_once_connected_and_answers(capsys):
    from affinity.commands.check import _cluster

    reach = _cluster(argparse.Namespace(scheduler="local:1", jobs=None), {}, show_dashboard=True)
    assert capsys.readouterr().err == ""  # nothing is started before there is a file to check
    with reach():
        said = capsys.readouterr().err
        assert said.startswith("Dask dashboard: http://127.0.0.1:") and said.count("\n") == 1
        with urllib.request.urlopen(said.split(": ", 1)[1].strip(), timeout=60) as page:
            assert page.status == 200
