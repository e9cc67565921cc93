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
  workers at once instead of waiting for their current files.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

PARENT_POLL_SECONDS = 0.2


@contextmanager
def local_pool(workers: int) -> Iterator:
    """A ``ProcessPoolExecutor`` of ``workers`` processes that end with this one; terminated on an early exit."""
    from concurrent.futures import ProcessPoolExecutor

    pool = ProcessPoolExecutor(max_workers=workers, initializer=end_with_parent)
    try:
        yield pool
    except BaseException:
        # No public way to stop busy workers before Python 3.14's terminate_workers().
        processes = list((pool._processes or {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.terminate()
        raise
    finally:
        pool.shutdown(wait=True)


def end_with_parent() -> None:
    """In a worker process: default SIGTERM, no SIGINT, and exit as soon as the parent is gone."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_POLL_SECONDS)
        os._exit(1)

    threading.Thread(target=watch, name="affinity-watch-parent", daemon=True).start()
