"""Checking files on a Dask cluster: ``affinity check --scheduler ADDRESS|env|local:N``.

Dask distributed does the scheduling; this module only turns files into
tasks and tasks back into reports:

- one task per file, carrying the file's settings; bigger files get a higher
  priority, so the long tasks start first and the short ones fill the gaps;
- a task carries the file's absolute path, not its bytes: workers read the
  shared storage (a network file system), and a worker that cannot see the
  path reports the file as unreadable (Q901) with that reason;
- reports stream back as tasks finish; :func:`affinity.pipeline.check.check_files`
  puts them back in the files' order, so the output is that of a local run;
- a worker lost mid-run is Dask's business: the scheduler reruns the tasks it
  held (``distributed.scheduler.allowed-failures`` times), and a task that
  still fails becomes an "internal error" report (transient: never cached).

``dask[distributed]`` is the optional extra ``distributed`` and is imported
only here, only when a scheduler is asked for.
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from ..errors import UsageError
from ..findings import FileReport
from ..settings import Settings

ENV_ADDRESS = "DASK_SCHEDULER_ADDRESS"
LOCAL_PREFIX = "local:"


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


def check_on_cluster(client, tasks: list[tuple[str, Settings]], check: Callable[..., FileReport],
                     usd=None) -> Iterator[tuple[int, FileReport]]:
    """``(task index, report)`` for every task, as the cluster finishes them; each task exactly once.

    ``check(path, settings, usd) -> FileReport`` checks one file on a worker
    (:func:`affinity.pipeline.check.check_file`, sent by reference: the workers import it).
    """
    from distributed import as_completed

    def size(path: str) -> int:
        try:
            return os.path.getsize(path)
        except OSError:
            return 0

    sizes = [size(path) for path, _ in tasks]
    biggest_first = sorted(range(len(tasks)), key=lambda j: -sizes[j])
    run = uuid.uuid4().hex[:12]
    futures = {}
    for rank, j in enumerate(biggest_first):
        path, settings = tasks[j]
        future = client.submit(_check_on_worker, check, os.path.abspath(path), path, settings, usd,
                               key=f"affinity-check-{run}-{j}", priority=len(tasks) - rank)
        futures[future] = j
    for future, result in as_completed(futures, with_results=True, raise_errors=False):
        j = futures.pop(future)
        if future.status != "finished":
            result = FileReport(tasks[j][0], error=f"internal error on the Dask cluster: {type(result).__name__}: "
                                                   f"{result}", transient=True)
        yield j, result
        future.release()


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
