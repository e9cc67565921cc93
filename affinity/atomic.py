"""Write output files whole or not at all, and never destroy what the path names.

- A regular file (or a new path) gets a temporary file beside it, renamed over
  it when complete; an existing file keeps its permission bits.
- A symbolic link is followed: its target is replaced that way, and the link
  stays a link.
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
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import stat
import sys
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
