"""Checking files on a Dask cluster: ``affinity check --scheduler ADDRESS|env|local:N``.

Dask distributed does the scheduling; this module only turns files into
tasks and tasks back into reports:

- files are batched into tasks of about :data:`BATCH_SECONDS` of work each, estimated from their
  sizes (:func:`batches`): Dask spends milliseconds scheduling a task, which one task per small
  file would pay again for every file, and graphs of millions of tasks are slow to start. Batches
  are smaller where the run is too small to give every worker several; the biggest files go first,
  so the long tasks start early and the short ones fill the gaps;
- a task carries its files' absolute paths, not their bytes: workers read the
  shared storage (a network file system), and a worker that cannot see a
  path reports the file as unreadable (Q901) with that reason;
- reports stream back as batches finish; :func:`affinity.pipeline.check.check_files`
  puts them back in the files' order, so the output is that of a local run;
- a worker lost mid-run is Dask's business: the scheduler reruns the batches it
  held (``distributed.scheduler.allowed-failures`` times), a batch that raises is
  retried :data:`BATCH_RETRIES` times, and one that still fails makes each of its files an
  "internal error" report (transient: never cached).

``dask[distributed]`` is the optional extra ``distributed`` and is imported
only here, only when a scheduler is asked for.
"""

from __future__ import annotations

import os
import time
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np

from ..errors import UsageError
from ..findings import FileReport
from ..settings import Settings

ENV_ADDRESS = "DASK_SCHEDULER_ADDRESS"
LOCAL_PREFIX = "local:"

#: The work one task aims at, in seconds of checking: Dask's per-task cost (about 13 ms here,
#: docs/cluster.md) is then well under 1 % of it, and a lost worker costs at most this much again.
BATCH_SECONDS = 10.0
#: At least this many tasks per worker where the run allows, so no worker waits on another's last batch.
BATCHES_PER_WORKER = 4
#: The estimate of one file's check: a fixed part (open, parse set-up, lint set-up, report) and a part per
#: byte, from lat-long sphere OBJs of 3 kB to 13 MB checked in one process on the developers' machine. A
#: batch only has to be right within a few times its target, so a rough fit serves every format.
FILE_SECONDS = 0.004
BYTES_PER_SECOND = 50e6
#: How many times Dask reruns a batch that raised (a lost worker is rerun by the scheduler besides).
BATCH_RETRIES = 2


def scheduler_address(spec: str) -> str:
    """The scheduler to use for ``--scheduler spec``: ``env`` reads ``DASK_SCHEDULER_ADDRESS``.

    A spec that names no scheduler (``env`` with the variable unset, ``local:0``)
    is a :class:`UsageError`; whether an address answers is :func:`connect`'s business.
    """
    address = spec
    if spec == "env":
        address = os.environ.get(ENV_ADDRESS, "").strip()
        if not address:
            raise UsageError(f"--scheduler env: {ENV_ADDRESS} is not set")
    if address.startswith(LOCAL_PREFIX):
        _local_workers(address)
    return address


def _local_workers(spec: str) -> int:
    count = spec[len(LOCAL_PREFIX):]
    if not count.isdigit() or int(count) < 1:
        raise UsageError(f"--scheduler {spec}: expected local:N with N a number of worker processes")
    return int(count)


@contextmanager
def connect(spec: str) -> Iterator:
    """A ``distributed.Client`` for ``spec``, closed (with its ``LocalCluster``, if any) on exit.

    ``local:N`` starts N single-threaded worker processes on 127.0.0.1. Any other
    address must answer within Dask's connect timeout
    (``distributed.comm.timeouts.connect``), else :class:`UsageError`.
    """
    import logging

    address = scheduler_address(spec)
    workers = _local_workers(address) if address.startswith(LOCAL_PREFIX) else None
    import dask
    from dask.utils import parse_timedelta
    from distributed import Client, LocalCluster

    if workers is not None:
        with (LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address="127.0.0.1:0", silence_logs=logging.ERROR) as cluster,
              Client(cluster) as client):
            yield client
        return
    timeout = parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), default="s")
    try:
        client = Client(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as err:
        reason = str(err).splitlines()[0] if str(err) else type(err).__name__
        raise UsageError(f"--scheduler {address}: no Dask scheduler answered within {timeout:g} s ({reason})") from None
    with client:
        yield client


def dashboard_link(client) -> str | None:
    """The cluster's dashboard address, or None when the scheduler serves none (e.g. without bokeh)."""
    services = client.scheduler_info().get("services", {})
    return client.dashboard_link if "dashboard" in services else None


def batches(sizes: list[int], workers: int, seconds: float = BATCH_SECONDS) -> list[list[int]]:
    """The files (indices into ``sizes``, file sizes in bytes) of each task, the biggest files first.

    A file's estimated check time is ``FILE_SECONDS + size / BYTES_PER_SECOND``; files join a batch,
    biggest first, until it holds ``seconds`` of work, or less where that would leave fewer than
    ``BATCHES_PER_WORKER`` batches per worker. A file alone over the target is a batch of its own.

    >>> batches([10, 10, 10, 10], workers=1, seconds=1.0)
    [[0], [1], [2], [3]]
    >>> [len(b) for b in batches([1000] * 10_000, workers=2)]  # 20 s of work: 8 batches, not 2
    [1250, 1250, 1250, 1250, 1250, 1250, 1250, 1250]
    >>> len(batches([1000] * 200_000, workers=2))  # 804 s of work in batches of 10 s
    81
    """
    if not sizes:
        return []
    cost = FILE_SECONDS + np.asarray(sizes, dtype=np.float64) / BYTES_PER_SECOND
    order = np.argsort(-cost, kind="stable")
    target = min(seconds, cost.sum() / (max(1, workers) * BATCHES_PER_WORKER))
    # Batch b holds the files whose running cost (biggest first) falls in [b * target, (b + 1) * target):
    # the cost before each file, over the target, is its batch; a file over the target opens a new one.
    before = np.concatenate([[0.0], np.cumsum(cost[order])[:-1]])
    slot = np.floor(before / target + 1e-9).astype(np.int64) if target > 0 else np.arange(len(order))
    starts = np.flatnonzero(np.diff(slot, prepend=-1))
    return [chunk.tolist() for chunk in np.split(order, starts[1:])]


def check_on_cluster(client, tasks: list[tuple[str, Settings]], check: Callable[..., FileReport],
                     usd=None, timings: list[float] | None = None,
                     batch_seconds: float = BATCH_SECONDS) -> Iterator[tuple[int, FileReport]]:
    """``(task index, report)`` for every task, as the cluster finishes their batches; each task exactly once.

    ``check(path, settings, usd) -> FileReport`` checks one file on a worker
    (:func:`affinity.pipeline.check.check_file`, sent by reference: the workers import it).
    ``timings``, when given, receives each file's check time on its worker, in seconds (what
    ``benchmarks/bench_farm.py`` weighs the cluster's overhead against); ``batch_seconds`` the work a
    batch aims at (:func:`batches`; 0: one task per file).
    """
    from distributed import as_completed

    from .files import file_size

    planned = batches([file_size(path) for path, _ in tasks], len(client.scheduler_info()["workers"]), batch_seconds)
    run = uuid.uuid4().hex[:12]
    futures = {}
    for rank, batch in enumerate(planned):
        files = [(os.path.abspath(tasks[j][0]), *tasks[j]) for j in batch]
        future = client.submit(_check_batch_on_worker, check, files, usd, key=f"affinity-check-{run}-{rank}",
                               priority=len(planned) - rank, retries=BATCH_RETRIES)
        futures[future] = batch
    for future, result in as_completed(futures, with_results=True, raise_errors=False):
        batch = futures.pop(future)
        if future.status != "finished":
            reason = f"internal error on the Dask cluster: {type(result).__name__}: {result}"
            result = [(FileReport(tasks[j][0], error=reason, transient=True), 0.0) for j in batch]
        for j, (report, seconds) in zip(batch, result):
            if timings is not None:
                timings.append(seconds)
            yield j, report
        future.release()


def _check_batch_on_worker(check: Callable[..., FileReport], files: list[tuple[str, str, Settings]],
                           usd) -> list[tuple[FileReport, float]]:
    """A worker's task: each ``(absolute, given, settings)`` file's report (:func:`_check_on_worker`) and the
    seconds its check took, in the batch's order."""
    results = []
    for absolute, given, settings in files:
        start = time.perf_counter()
        report = _check_on_worker(check, absolute, given, settings, usd)
        results.append((report, time.perf_counter() - start))
    return results


def _check_on_worker(check: Callable[..., FileReport], absolute: str, given: str, settings: Settings,
                     usd) -> FileReport:
    """A worker's task: ``check`` the file at ``absolute``; the report names it ``given`` as the client does."""
    if not os.path.exists(absolute):
        import socket

        return FileReport(given, error=f"not found on the Dask worker on {socket.gethostname()} "
                                       f"(is the shared storage mounted there at {os.path.dirname(absolute)}?)",
                          transient=True)
    report = check(absolute, settings, usd)
    report.path = given
    return report
