"""Run a native reader where its crash costs one file: a forked child process, bounded in memory and time.

A reader in C (ufbx for FBX) that a hostile file drives into a segmentation fault
would take the whole check down with it. :func:`read_isolated` forks, runs the
reader in the child under ``RLIMIT_AS`` (memory) and ``RLIMIT_CPU`` (time), and
hands its result back through a file in memory (``memfd``): a pickle whose NumPy
arrays travel out of band (protocol 5), each written once by the child and mapped
by the parent (copy-on-write), where its array then lives: no copy, and no pipe
whose every 64 kB waits for the other process to be scheduled (on a busy machine,
seconds for a million quads). A child that dies (a signal, the limits) or does not
finish its answer is a :class:`~affinity.errors.MeshError` for that file only.
Forking copies nothing up front (copy-on-write).

Where there is no ``os.fork`` (Windows) the reader runs in this process.
"""

from __future__ import annotations

import faulthandler
import gc
import mmap
import os
import pickle
import signal
import struct
import tempfile
import time
from collections.abc import Callable

from ..errors import MeshError, SkippedFile

#: Address space the child may add to what it inherits, plus this many times the file's size.
MEMORY_BASE = 2 << 30
MEMORY_PER_BYTE = 64
#: CPU seconds the child may use, plus one per this many bytes of the file.
SECONDS_BASE = 30
BYTES_PER_SECOND = 1 << 20
#: Wall-clock seconds the parent waits, in CPU seconds the child may use: a child that neither works nor
#: ends (a lock some other thread of the parent held when it forked) is killed.
WALL_FACTOR = 10

_HEADER = struct.Struct("<QQ")  # pickle length, number of out-of-band buffers
_PLACE = struct.Struct("<QQ")  # an out-of-band buffer's offset in the answer and its length


def read_isolated(path: str, read: Callable, *args):
    """``read(*args)`` run in a forked child; its result, or the MeshError/SkippedFile it raised.

    The result must pickle. A child killed by a signal, over its limits or without an answer is a
    MeshError (line 0) naming what happened.
    """
    if not hasattr(os, "fork"):
        return read(*args)
    size = _file_size(path)
    with _answer_file() as answer_file:
        pid = os.fork()
        if pid == 0:  # the child: never returns
            _child(answer_file.fileno(), size, read, args)
        status = _waited(pid, WALL_FACTOR * _cpu_seconds(size))
        answer = _received(answer_file.fileno()) if os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0 else None
    if answer is None:
        raise MeshError(path, 0, f"the reader stopped without an answer ({_how_it_ended(status)})")
    kind, *rest = answer
    if kind == "mesh":
        return rest[0]
    if kind == "skipped":
        raise SkippedFile(path, rest[0])
    raise MeshError(path, *rest)


def _answer_file():
    """A file in memory (``memfd``; elsewhere a temporary file) the child writes its answer to."""
    if hasattr(os, "memfd_create"):
        return open(os.memfd_create("affinity-reader-answer"), "w+b", buffering=0)
    return tempfile.TemporaryFile()


def _child(answer: int, size: int, read: Callable, args) -> None:
    """Run ``read`` within the limits and write its answer to the file ``answer``; exit without Python's
    clean-up (0 once the whole answer is written)."""
    code = 1
    try:
        gc.disable()  # the child lives for one read: nothing to collect, and native readers' wrappers may not bear it
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        faulthandler.disable()  # a crash here is the parent's one line, not a dump on the shared stderr
        _limit(size)
        try:
            result = ("mesh", read(*args))
        except MeshError as error:
            result = ("error", error.line, error.reason)
        except SkippedFile as skip:
            result = ("skipped", skip.reason)
        except MemoryError:
            result = ("error", 0, "the reader ran out of memory")
        except Exception as error:  # a reader's exception is about this file: one line, never a traceback
            result = ("error", 0, " ".join(f"cannot read: {type(error).__name__}: {error}".split())[:300])
        buffers = []
        payload = pickle.dumps(result, protocol=5, buffer_callback=buffers.append)
        views = [buffer.raw() for buffer in buffers]
        offsets, offset = [], _aligned(_HEADER.size + _PLACE.size * len(views) + len(payload))
        for view in views:
            offsets.append(offset)
            offset = _aligned(offset + view.nbytes)
        with open(answer, "wb", closefd=False) as out:
            out.write(_HEADER.pack(len(payload), len(views)))
            out.write(b"".join(_PLACE.pack(at, view.nbytes) for at, view in zip(offsets, views)))
            out.write(payload)
            for at, view in zip(offsets, views):
                out.seek(at)
                out.write(view)
        code = 0
    except BaseException:  # e.g. an answer that does not pickle: the parent reports the missing answer
        code = 1
    finally:
        os._exit(code)


def _aligned(offset: int) -> int:
    """``offset`` rounded up to a multiple of 64 bytes, where an array's data starts."""
    return -(-offset // 64) * 64


def _limit(size: int) -> None:
    """The child's limits: address space and CPU seconds growing with the file (see the constants)."""
    import resource

    memory = _address_space() + MEMORY_BASE + MEMORY_PER_BYTE * size
    seconds = _cpu_seconds(size)
    for which, limit in ((resource.RLIMIT_AS, memory), (resource.RLIMIT_CPU, seconds)):
        _, hard = resource.getrlimit(which)
        resource.setrlimit(which, (limit if hard == resource.RLIM_INFINITY else min(limit, hard), hard))


def _cpu_seconds(size: int) -> int:
    """CPU seconds the child may use for a file of ``size`` bytes."""
    return SECONDS_BASE + size // BYTES_PER_SECOND


def _waited(pid: int, seconds: float) -> int:
    """The wait status of child ``pid`` once it ends, killed (SIGKILL) after ``seconds`` of wall-clock time."""
    deadline, pause = time.monotonic() + seconds, 0.0005
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return status
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            return os.waitpid(pid, 0)[1]
        time.sleep(pause)
        pause = min(2 * pause, 0.02)


def _address_space() -> int:
    """Bytes of address space this process has now (``/proc/self/statm``; 0 where there is none)."""
    try:
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _received(answer: int):
    """The child's answer from the file ``answer``, its arrays over a copy-on-write mapping of it (no copy);
    None when the file does not hold a whole answer."""
    length = os.fstat(answer).st_size
    if length < _HEADER.size:
        return None
    mapped = mmap.mmap(answer, length, access=mmap.ACCESS_COPY)
    data = memoryview(mapped)
    size, count = _HEADER.unpack_from(data)
    table = _HEADER.size + _PLACE.size * count
    if table > length:
        return None
    places = list(_PLACE.iter_unpack(data[_HEADER.size:table]))
    if table + size > length or any(at + n > length for at, n in places):
        return None
    return pickle.loads(data[table:table + size], buffers=[data[at:at + n] for at, n in places])


def _how_it_ended(status: int) -> str:
    """The child's end in words: ``killed by SIGSEGV``, ``over its CPU time``, ``exit code 1``."""
    if os.WIFSIGNALED(status):
        number = os.WTERMSIG(status)
        if number == signal.SIGXCPU:
            return "over its CPU time"
        return f"killed by {signal.Signals(number).name}" if number in signal.Signals._value2member_map_ \
            else f"killed by signal {number}"
    return f"exit code {os.WEXITSTATUS(status)}"


def _file_size(path: str) -> int:
    try:
        return os.path.getsize(path)
    except OSError:
        return 0
