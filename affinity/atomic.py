"""Write output files whole or not at all, and never destroy what the path names.

- A regular file (or a new path) gets a temporary file beside it, renamed over
  it when complete; an existing file keeps its permission bits.
- A symbolic link is followed: its target is replaced that way, and the link
  stays a link (commands refuse such a destination first: below).
- A character device, FIFO or socket (``-o /dev/stdout``, ``-o /dev/null``, a
  named pipe) cannot be replaced: the whole output is built in memory and
  written to it once, so a failure while producing it writes nothing.
- A directory is refused (``IsADirectoryError``) before anything is produced.
- ``-`` is standard output (the command-line convention: ``-o -``), written
  once like a device; a file named ``-`` is ``./-``.

The temporary file is ``.NAME.PID-RANDOM.tmp``: it is removed when the
writer fails, is interrupted or gets SIGTERM (see
:func:`affinity.cli.console_main`); one left by a writer that was killed
outright (SIGKILL, a power cut) is removed by the next write to NAME, once no
process PID is running.

Commands check their destinations first (:func:`refuse_unsafe`): an output path
(``affinity fix``'s default ``NAME.fixed.EXT``, the ``-o`` of check, merge, render, report and
fix) that is a symbolic link to a file, or to nothing yet, is refused: an asset repository that
commits ``vase.fixed.obj -> vase.obj`` (or a link to any other file) would otherwise turn a fix
in CI into a write of the link's target. A link to a device, FIFO or socket is a stream and is
written as above; so is a link to one of the process's own descriptors (``-o /dev/stdout``, a
link to ``/proc/self/fd/1``, whatever the shell redirected it to). A path that resolves (links,
``..``) to one of the run's inputs is refused too, so no input is replaced before it is read
(``affinity fix a.obj a.fixed.obj``); ``--in-place`` asks for its own input to be replaced.
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import stat
import sys
from collections.abc import Iterable
from pathlib import Path

#: The output path that means standard output.
STDOUT = "-"


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _existing_mode(path: Path) -> int | None:
    """``st_mode`` of what ``path`` names (links followed), None when nothing is there."""
    try:
        return os.stat(path).st_mode
    except FileNotFoundError:
        return None


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, binary: bool = False):
    """Yield a file object (text: UTF-8, '\\n' line ends); on success the output is at ``path``.

    See the module docstring for what each kind of ``path`` gets. Raises
    ``OSError`` before anything is written when the folder does not exist or
    is not writable, or ``path`` is a directory, so callers can turn it into
    one clear line.
    """
    if os.fspath(path) == STDOUT:
        with _write_once(None, binary) as out:
            yield out
        return
    mode = _existing_mode(Path(path))
    if mode is not None and stat.S_ISDIR(mode):
        raise IsADirectoryError(errno.EISDIR, "is a directory, not a file", os.fspath(path))
    if mode is not None and not stat.S_ISREG(mode):
        # through the path as given: /dev/stdout on a pipe resolves to no file name
        with _write_once(Path(path), binary) as out:
            yield out
        return
    target = Path(os.path.realpath(path))
    import tempfile  # here, not at import: it pulls in shutil, random and the compression modules

    _remove_stale_temporaries(target)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.{os.getpid()}-", suffix=".tmp")
    try:
        os.fchmod(fd, stat.S_IMODE(mode) if mode is not None else 0o666 & ~_umask())
        with os.fdopen(fd, "wb" if binary else "w", **({} if binary else {"encoding": "utf-8", "newline": "\n"})) as f:
            yield f
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _remove_stale_temporaries(target: Path) -> None:
    """Remove the ``.NAME.PID-RANDOM.tmp`` files beside ``target`` whose writer PID is no longer running."""
    if os.name != "posix":  # os.kill(pid, 0) would end the process on Windows
        return
    prefix = f".{target.name}."
    try:
        names = [entry.name for entry in os.scandir(target.parent)
                 if entry.name.startswith(prefix) and entry.name.endswith(".tmp")]
    except OSError:
        return  # mkstemp says what is wrong with the folder
    for name in names:
        pid = name[len(prefix) : -len(".tmp")].partition("-")[0]
        if not pid.isdigit() or int(pid) == os.getpid():
            continue  # not one of ours, or this process's own
        try:
            os.kill(int(pid), 0)
        except ProcessLookupError:
            with contextlib.suppress(OSError):
                os.unlink(target.parent / name)
        except OSError:
            pass  # running under another user


@contextlib.contextmanager
def _write_once(target: Path | None, binary: bool):
    """Collect the output in memory, then write it to the device or pipe ``target`` (None: standard
    output) in one go."""
    buffer = io.BytesIO() if binary else io.StringIO(newline="\n")
    yield buffer
    data = buffer.getvalue()
    if target is None:
        if binary:
            sys.stdout.flush()  # what was printed before comes first
            sys.stdout.buffer.write(data)
            sys.stdout.buffer.flush()
        else:
            sys.stdout.write(data)
        return
    data = data if binary else data.encode("utf-8")
    with open(target, "wb", buffering=0) as out:
        view = memoryview(data)
        while view:  # a pipe may take less than everything at once
            view = view[out.write(view):]


class UnsafeDestination(OSError):
    """An output path refused; ``strerror`` says why, in words that follow the path."""

    def __init__(self, path, reason: str):
        super().__init__(errno.EPERM, reason, os.fspath(path))


def refuse_unsafe(path, inputs: Iterable = ()) -> None:
    """Raise :class:`UnsafeDestination` when ``path`` is a symbolic link to a file (or a dangling one), or
    resolves to one of ``inputs`` (paths of the run's input files); return quietly otherwise."""
    if os.fspath(path) == STDOUT or _descriptor(os.fspath(path)):
        return
    try:
        link = os.lstat(path)
    except OSError:
        link = None
    if link is not None and stat.S_ISLNK(link.st_mode):
        try:
            target_mode = os.stat(path).st_mode
        except OSError:
            target_mode = None
        streams = target_mode is not None and not (stat.S_ISREG(target_mode) or stat.S_ISDIR(target_mode))
        if not streams and not _descriptor(os.readlink(path)):
            raise UnsafeDestination(path, f"is a symbolic link (to {os.readlink(path)}): an output is never "
                                          "written through a link; remove it or name a plain file")
    real = os.path.realpath(path)
    for source in inputs:
        if os.path.realpath(source) == real:
            raise UnsafeDestination(path, f"is the input {os.fspath(source)}: an output never replaces an input")


def _descriptor(name: str) -> bool:
    """Whether ``name`` names one of the process's own open descriptors (``/dev/stdout``, ``/dev/fd/N``).

    >>> _descriptor("/proc/self/fd/1"), _descriptor("/dev/stderr"), _descriptor("out.json")
    (True, True, False)
    """
    return name.startswith(_DESCRIPTORS) or name in ("/dev/stdout", "/dev/stderr")


#: Where a link to one of the process's open descriptors points.
_DESCRIPTORS = ("/proc/self/fd/", "/dev/fd/")
