"""Run a native reader where its crash costs one file: a forked child process, bounded in memory and time.

A reader in C (ufbx for FBX) that a hostile file drives into a segmentation fault
would take the whole check down with it. :func:`read_isolated` forks, runs the
reader in the child under ``RLIMIT_AS`` (memory) and ``RLIMIT_CPU`` (time), and
hands its result back through a pipe: a pickle whose NumPy arrays travel out of
band (protocol 5), each read straight into the buffer the parent's array then
uses, so a million-quad mesh costs one copy. A child that dies (a signal, the
limits) or says nothing is a :class:`~affinity.errors.MeshError` for that file
only. Forking copies nothing up front (copy-on-write); a measured million-quad
FBX pays about 0.1 s for the fork and the transfer (benchmarks/bench_fbx.py).

Where there is no ``os.fork`` (Windows) the reader runs in this process.
"""

from __future__ import annotations

import gc
import os
import pickle
import signal
import struct
from collections.abc import Callable

from ..errors import MeshError, SkippedFile

#: Address space the child may add to what it inherits, plus this many times the file's size.
MEMORY_BASE = 2 << 30
MEMORY_PER_BYTE = 64
#: CPU seconds the child may use, plus one per this many bytes of the file.
SECONDS_BASE = 30
BYTES_PER_SECOND = 1 << 20

_HEADER = struct.Struct("<QQ")  # pickle length, number of out-of-band buffers
_LENGTH = struct.Struct("<Q")


def read_isolated(path: str, read: Callable, *args):
    """``read(*args)`` run in a forked child; its result, or the MeshError/SkippedFile it raised.

    The result must pickle. A child killed by a signal, over its limits or without an answer is a
    MeshError (line 0) naming what happened.
    """
    if not hasattr(os, "fork"):
        return read(*args)
    size = _file_size(path)
    receive, send = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        os.close(receive)
        _child(send, size, read, args)
    os.close(send)
    try:
        with open(receive, "rb", buffering=0) as pipe:
            answer = _received(pipe)
    finally:
        _, status = os.waitpid(pid, 0)
    if answer is None:
        raise MeshError(path, 0, f"the reader stopped without an answer ({_how_it_ended(status)})")
    kind, *rest = answer
    if kind == "mesh":
        return rest[0]
    if kind == "skipped":
        raise SkippedFile(path, rest[0])
    raise MeshError(path, *rest)


def _child(send: int, size: int, read: Callable, args) -> None:
    """Run ``read`` within the limits and write its answer to ``send``; exit without Python's clean-up."""
    code = 0
    try:
        gc.disable()  # the child lives for one read: nothing to collect, and native readers' wrappers may not bear it
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        _limit(size)
        try:
            answer = ("mesh", read(*args))
        except MeshError as error:
            answer = ("error", error.line, error.reason)
        except SkippedFile as skip:
            answer = ("skipped", skip.reason)
        except MemoryError:
            answer = ("error", 0, "the reader ran out of memory")
        except Exception as error:  # a reader's exception is about this file: one line, never a traceback
            answer = ("error", 0, " ".join(f"cannot read: {type(error).__name__}: {error}".split())[:300])
        buffers = []
        payload = pickle.dumps(answer, protocol=5, buffer_callback=buffers.append)
        views = [buffer.raw() for buffer in buffers]
        with open(send, "wb", buffering=0) as pipe:
            pipe.write(_HEADER.pack(len(payload), len(views)))
            pipe.write(b"".join(_LENGTH.pack(view.nbytes) for view in views))
            pipe.write(payload)
            for view in views:
                pipe.write(view)
    except BaseException:  # e.g. an answer that does not pickle: the parent reports the missing answer
        code = 1
    finally:
        os._exit(code)


def _limit(size: int) -> None:
    """The child's limits: address space and CPU seconds growing with the file (see the constants)."""
    import resource

    in_use = _address_space()
    memory = in_use + MEMORY_BASE + MEMORY_PER_BYTE * size
    seconds = SECONDS_BASE + size // BYTES_PER_SECOND
    for which, limit in ((resource.RLIMIT_AS, memory), (resource.RLIMIT_CPU, seconds)):
        _, hard = resource.getrlimit(which)
        resource.setrlimit(which, (limit if hard == resource.RLIM_INFINITY else min(limit, hard), hard))


def _address_space() -> int:
    """Bytes of address space this process has now (``/proc/self/statm``; 0 where there is none)."""
    try:
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _read_exactly(pipe, n: int) -> bytearray | None:
    """``n`` bytes from ``pipe`` into a new buffer; None when it ends first."""
    buffer = bytearray(n)
    view, got = memoryview(buffer), 0
    while got < n:
        count = pipe.readinto(view[got:])
        if not count:
            return None
        got += count
    return buffer


def _received(pipe):
    """The child's answer from the pipe, its arrays over the buffers read for them; None when incomplete."""
    header = _read_exactly(pipe, _HEADER.size)
    if header is None:
        return None
    length, count = _HEADER.unpack(header)
    sizes = _read_exactly(pipe, _LENGTH.size * count)
    payload = _read_exactly(pipe, length)
    if sizes is None or payload is None:
        return None
    buffers = []
    for (nbytes,) in _LENGTH.iter_unpack(sizes):
        buffer = _read_exactly(pipe, nbytes)
        if buffer is None:
            return None
        buffers.append(buffer)
    return pickle.loads(payload, buffers=buffers)


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
