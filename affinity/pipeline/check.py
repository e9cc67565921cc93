"""Check files: lint each one, collect one report per file.

Each file is checked independently; an unreadable file becomes a report with an
``error`` and never stops the others. Files are checked in parallel across
processes (``--jobs``); the reports come back in the order of the files, however
the workers were scheduled.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from contextlib import AbstractContextManager, nullcontext
from functools import partial

from ..errors import MeshError, SkippedFile, internal_error
from ..findings import FileReport
from ..mesh import Mesh
from ..settings import Settings
from .files import file_size


def check_file(path: str, settings: Settings, usd=None, source: bytes | None = None) -> FileReport:
    """Load and lint one file; never raises for bad input.

    ``usd`` (:class:`affinity.loaders.usd.UsdOptions`) says how to read USD stages.
    ``source`` is the file's bytes when the caller has read them (the cache, to hash
    them): an OBJ file is read once, by whoever reads it first.
    """
    return load_and_check(path, settings, usd, source)[0]


def load_and_check(path: str, settings: Settings, usd=None, source: bytes | None = None,
                   scores: bool = False) -> tuple[FileReport, Mesh | None]:
    """:func:`check_file`, also handing back the loaded mesh (None when it could not be read); with ``scores``,
    the report holds every quad's scores from the same lint (:attr:`FileReport.scores`)."""
    from ..lint import mesh_report
    from ..loaders import load, reads_whole
    from ..loaders.sidefiles import forget

    try:
        if reads_whole(path):
            source = whole_source(path) if source is None else source
        else:
            source = None  # the other loaders read their files themselves
        mesh = load(path, usd, source)
        ignores = _inline_ignores(source, mesh) if reads_whole(path) else []
        del source  # not needed past here: a big file's bytes are not held while its mesh is linted
        report = mesh_report(path, mesh, settings, ignores, scores)
    except SkippedFile as skip:
        return FileReport(path, skipped=skip.reason), None
    except MeshError as err:
        return FileReport(path, error=err.reason, error_line=err.line), None
    except Exception as err:
        return FileReport(path, error=internal_error(err), error_line=0, transient=True), None
    finally:
        forget()  # the side files' bytes served this file's readers; the next file reads its own
    return report, mesh


def whole_source(path: str):
    """The bytes of the file at ``path`` for a loader that parses them whole: mapped when the
    file can be (no copy of a big file), else read (MeshError when it cannot be)."""
    from ..loaders import read_source
    from ..loaders.text import mapped_file

    mapped = mapped_file(path)
    return read_source(path) if mapped is None else mapped


def _inline_ignores(source: bytes, mesh: Mesh) -> list:
    """The ``# affinity: ignore[...]`` comments of an OBJ file's bytes (see :mod:`affinity.loaders.suppress`)."""
    from ..loaders.suppress import inline_ignores

    return inline_ignores(source, mesh.face_line)


#: Mesh bytes that pay for one more worker process: starting one costs about as
#: much as checking 1 MB of OBJ, so small pre-commit runs stay in one process.
BYTES_PER_WORKER = 2_000_000


def available_cpus() -> int:
    """The number of CPUs this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def auto_jobs(paths: list[str]) -> int:
    """Worker processes for ``paths`` when ``--jobs`` is not given: every CPU, if the files are big enough."""
    return max(1, min(available_cpus(), 1 + sum(map(file_size, paths)) // BYTES_PER_WORKER))



def check_files(
    tasks: list[tuple[str, Settings]],
    jobs: int | None = None,
    progress: Callable[[Iterable[tuple[int, FileReport]], int], Iterator[tuple[int, FileReport]]] | None = None,
    usd=None,
    cache=None,
    cluster: Callable[[], AbstractContextManager] | None = None,
) -> list[FileReport]:
    """Check ``(path, settings)`` pairs with up to ``jobs`` processes; reports in task order.

    ``jobs`` None picks :func:`auto_jobs`. One file or one job stays in this
    process (no pool start-up). ``progress``, when given, wraps the stream of
    ``(task index, report)`` pairs as they finish (e.g. a progress bar) and
    receives the number of tasks. ``usd`` is passed on to :func:`check_file`.
    ``cache`` (:class:`affinity.pipeline.cache.ResultCache`) answers for the
    unchanged files before anything is checked, and keeps the new reports.
    ``cluster``, when given, checks the files on a Dask cluster instead of
    ``jobs`` local processes (:mod:`affinity.pipeline.cluster`): called only
    when some file is not in the cache, it returns a context manager giving a
    ``dask.distributed.Client``, e.g. ``lambda: cluster.connect("local:2")``.
    """
    if cache is not None and cluster is None and _workers(tasks, jobs) <= 1:
        stream = _check_cached_here(tasks, usd, cache)
        reports: list[FileReport | None] = [None] * len(tasks)
        for i, report in _tracked(stream, len(tasks), progress):
            reports[i] = report
        return reports
    keys = [None] * len(tasks) if cache is None else [cache.key(path, s, usd) for path, s in tasks]
    known = {} if cache is None else {i: hit for i, key in enumerate(keys) if (hit := cache.get(key)) is not None}
    todo = [i for i in range(len(tasks)) if i not in known]
    with cluster() if cluster is not None and todo else nullcontext() as client:
        if client is not None:
            from .cluster import check_on_cluster

            fresh = check_on_cluster(client, [tasks[i] for i in todo], check_file, usd)
        else:
            fresh = enumerate(_check_here([tasks[i] for i in todo], jobs, usd))
        reports = [None] * len(tasks)
        for i, report in _tracked(_chain(known, todo, fresh), len(tasks), progress):
            reports[i] = report
            if cache is not None and i not in known:
                cache.put(keys[i], report)
    return reports


def _check_cached_here(tasks: list[tuple[str, Settings]], usd, cache) -> Iterator[tuple[int, FileReport]]:
    """``(task index, report)`` of every task, in this process, each file read at most once:
    the bytes the cache hashes (a file changed since its pre-key) are the bytes the loader parses."""
    from ..loaders import read_source, reads_whole

    for i, (path, settings) in enumerate(tasks):
        read = []

        def source(path=path, read=read) -> bytes:
            read.append(read_source(path))
            return read[0]

        key = cache.key(path, settings, usd, source if reads_whole(path) else None)
        report = cache.get(key)
        if report is None:
            report = check_file(path, settings, usd, source=read[0]) if read else check_file(path, settings, usd)
            cache.put(key, report)
        yield i, report


def _chain(known: dict, todo: list[int], fresh) -> Iterator[tuple[int, FileReport]]:
    """The cached reports first, then the fresh ones (numbered within ``todo``) as task indices."""
    yield from known.items()
    for j, report in fresh:
        yield todo[j], report


def _workers(tasks: list[tuple[str, Settings]], jobs: int | None) -> int:
    """Processes that check ``tasks``: ``jobs``, else :func:`auto_jobs`, at most one a task."""
    return min(auto_jobs([path for path, _ in tasks]) if jobs is None else jobs, len(tasks))


def _check_here(tasks: list[tuple[str, Settings]], jobs: int | None, usd) -> Iterator[FileReport]:
    """The reports of ``tasks`` in order, checked in this process or a local process pool."""
    check = partial(check_file, usd=usd)
    workers = _workers(tasks, jobs)
    if workers <= 1:
        yield from (check(path, settings) for path, settings in tasks)
        return

    from .. import lint, loaders  # noqa: F401  imported before the workers fork, so each inherits them
    from .workers import map_in_workers

    # Small chunks balance uneven file sizes; a few per worker keep the pickling overhead low.
    chunksize = max(1, len(tasks) // (workers * 8))
    yield from map_in_workers(check, tasks, workers, chunksize, _worker_died)


#: The Q901 reason of a file whose check killed its worker, and a fresh worker after it.
WORKER_DIED = "worker died while checking it, and again in a fresh worker (killed, out of memory, or a crash)"


def _worker_died(task: tuple[str, Settings]) -> FileReport:
    return FileReport(task[0], error=WORKER_DIED, error_line=0, transient=True)


def _tracked(results: Iterator, total: int, progress) -> Iterator:
    return results if progress is None else progress(results, total)
