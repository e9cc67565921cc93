"""Process-wide allocator tuning, applied by the command line (never by the library on import)."""

from __future__ import annotations

import ctypes
import functools
import os

#: BLAS libraries' thread-count variables; each is read once, when the library loads with NumPy.
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def one_blas_thread() -> None:
    """Run BLAS on one thread unless the environment says otherwise; call it before NumPy is imported.

    The products here are tall and thin ((V, 3) points by a (3, 4) matrix): memory-bound,
    so a second BLAS thread gains nothing, and OpenBLAS's threads spin-wait for each
    other. Measured for 100,000 points on 2 cores: 1.1 ms on one thread, 38 ms on two
    when the other core is busy; the car report (100,800 quads, 70 renders) spent
    2.1 s in that product. Once NumPy is imported the setting has no effect.
    """
    for name in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(name, "1")


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
