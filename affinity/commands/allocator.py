"""Process-wide allocator tuning, applied by the command line (never by the library on import)."""

from __future__ import annotations

import ctypes
import functools


@functools.cache
def keep_freed_memory() -> None:
    """Let glibc reuse freed memory instead of returning it to the OS at once.

    Called once by ``affinity.cli.main``: the command line owns its process, a
    library user's process is left alone.

    Parsing a chunk allocates and frees dozens of NumPy temporaries of a few
    hundred KB. glibc's defaults map each afresh and give it back, and the page
    faults then cost as much as the parsing (measured: 280k faults and 0.7 s of
    system time for a 166 MB OBJ, 70k and 0.3 s with these settings). Peak
    memory is unchanged; at most 256 MB of freed heap stays with the process.
    A no-op where glibc's ``mallopt`` is not available.

    It also turns off NumPy's transparent-huge-page advice for big arrays: on a
    kernel that compacts memory to back such a fault (``defrag`` = ``madvise``,
    the default), a busy machine's faults then stall; measured on the 166 MB OBJ:
    0.2-0.3 s of system time instead of 0.3-0.7 s, and the load 10-30% faster.
    """
    _ordinary_pages_for_numpy()
    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError, TypeError):
        return
    m_trim_threshold, m_mmap_threshold = -1, -3
    mallopt(m_mmap_threshold, 32 << 20)
    mallopt(m_trim_threshold, 256 << 20)


def _ordinary_pages_for_numpy() -> None:
    """NumPy's big allocations without ``madvise(MADV_HUGEPAGE)`` (a no-op where NumPy lacks the switch)."""
    try:
        from numpy._core import multiarray
    except ImportError:  # NumPy 1.x
        from numpy.core import multiarray
    switch = getattr(multiarray, "_set_madvise_hugepage", None)
    if switch is not None:
        switch(False)
