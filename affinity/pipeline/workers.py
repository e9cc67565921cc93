"""Local worker processes (``--jobs``) that never outlive the run that started them.

A ``ProcessPoolExecutor`` worker waits for work on a pipe that its siblings
also hold open, so it never sees its parent die: after a SIGKILL or SIGTERM to
``affinity check -j 2`` the workers used to stay, blocked, for good. Here

- each worker watches its parent: a daemon thread polls ``os.getppid()`` every
  :data:`PARENT_POLL_SECONDS` and ends the process when it changes (the parent
  died, whatever killed it, and the worker was handed to init);
- a worker takes SIGTERM's default action (the parent's handler, inherited
  through ``fork``, would unwind a half-finished check) and ignores SIGINT (a
  Ctrl-C reaches the whole process group; the parent answers it);
- when the run ends early (an exception, SIGTERM turned into ``SystemExit`` by
  :func:`affinity.cli.console_main`, Ctrl-C), :func:`local_pool` terminates the
  workers at once instead of waiting for their current files, and does not wait
  for the pool's result reader either: a worker terminated in the middle of
  sending a result leaves half a message in the pipe, which the reader would wait
  on for good (the parent holds the pipe's write end too). The parent's write end
  is closed, so the reader sees the end of the pipe and stops.

A worker that dies (killed, out of memory, a crash in native code) breaks the
whole pool. :func:`map_in_workers` then carries on in a fresh pool: the tasks
that were running when it broke (every worker's, since the pool ends them all)
are each run once more alone in a fresh worker, and a task that kills that one
too is reported by ``lost``; the tasks that had not started are run as before.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

PARENT_POLL_SECONDS = 0.2


#: Seconds an early exit waits for its terminated workers to end.
TERMINATE_SECONDS = 2.0
#: Per task of :func:`map_in_workers`, shared with the workers: not started, running, done.
WAITING, RUNNING, DONE = 0, 1, 2
_progress = None  # in a worker: the shared (tasks,) int8 states of the tasks of map_in_workers


@contextmanager
def local_pool(workers: int, progress=None) -> Iterator:
    """A ``ProcessPoolExecutor`` of ``workers`` processes that end with this one; terminated on an early exit.
    ``progress`` is the shared task states of :func:`map_in_workers`, handed to every worker."""
    from concurrent.futures import ProcessPoolExecutor

    pool = ProcessPoolExecutor(max_workers=workers, initializer=end_with_parent, initargs=(progress,))
    try:
        yield pool
    except BaseException:
        # No public way to stop busy workers before Python 3.14's terminate_workers().
        processes, results = list((pool._processes or {}).values()), pool._result_queue
        pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.terminate()
        for process in processes:
            process.join(TERMINATE_SECONDS)
        if results is not None:
            results._writer.close()  # the reader may wait on half a message: let it see the end
        raise
    pool.shutdown(wait=True)


def map_in_workers(function, tasks: list[tuple], workers: int, chunksize: int, lost) -> Iterator:
    """``function(*task)`` of each of ``tasks``, in task order, computed in ``workers`` processes (chunks of
    ``chunksize`` tasks); ``lost(task)`` stands for the result of a task that killed its worker twice (see
    the module docstring)."""
    import multiprocessing
    from concurrent.futures.process import BrokenProcessPool

    progress = multiprocessing.Array("b", len(tasks), lock=False)
    results: dict[int, object] = {}
    todo, suspects, emitted = list(range(len(tasks))), [], 0
    while todo:
        with local_pool(workers, progress) as pool:
            chunks = [todo[k : k + chunksize] for k in range(0, len(todo), chunksize)]
            futures = [(pool.submit(_run_chunk, function, chunk, [tasks[i] for i in chunk]), chunk) for chunk in chunks]
            todo = []
            for future, chunk in futures:
                try:
                    results.update(zip(chunk, future.result()))
                except BrokenProcessPool:
                    suspects += [i for i in chunk if progress[i] == RUNNING]
                    todo += [i for i in chunk if progress[i] != RUNNING]
                while emitted in results:
                    yield results.pop(emitted)
                    emitted += 1
    for i in suspects:  # each alone in a fresh worker: a second death is its own
        with local_pool(1, progress) as pool:
            try:
                (results[i],) = pool.submit(_run_chunk, function, [i], [tasks[i]]).result()
            except BrokenProcessPool:
                results[i] = lost(tasks[i])
    while emitted < len(tasks):
        yield results.pop(emitted)
        emitted += 1


def _run_chunk(function, indices: list[int], tasks: list[tuple]) -> list:
    """In a worker: ``function(*task)`` of each task, marking each running, then done, in the shared states."""
    values = []
    for i, task in zip(indices, tasks):
        _progress[i] = RUNNING
        values.append(function(*task))
        _progress[i] = DONE
    return values


def end_with_parent(progress=None) -> None:
    """In a worker process: default SIGTERM, no SIGINT, and exit as soon as the parent is gone; ``progress``
    is kept for :func:`_run_chunk`."""
    global _progress
    _progress = progress
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_POLL_SECONDS)
        os._exit(1)

    threading.Thread(target=watch, name="affinity-watch-parent", daemon=True).start()
