"""Opening a file the tools read: a regular file only, read within a size budget.

Every path the tools open (meshes, material libraries, textures, USD layers) goes
through :func:`open_regular`: a FIFO would block the read forever, a device
(``/dev/zero``, ``/dev/urandom``) would be read without end, a socket cannot be
read at all. The file is opened without blocking (``O_NONBLOCK``: opening a FIFO
with no writer returns at once) and its kind is taken from the open descriptor
(``fstat``), so a path swapped for a FIFO between a look and the open is refused too.

Side files (a mesh's material libraries, a texture's header) are read with
:func:`read_regular` and a byte budget: a file over it is refused before any
of it is read, with its size in the reason.
"""

from __future__ import annotations

import os
import stat

#: Bytes a side file (an MTL material library) may hold. Real libraries are kilobytes; a
#: library of 16 MiB names some 200,000 texture maps, more than any mesh needs.
SIDE_FILE_BUDGET = 16 << 20

_KINDS = (
    (stat.S_ISDIR, "is a directory"),
    (stat.S_ISFIFO, "is a FIFO (named pipe)"),
    (stat.S_ISSOCK, "is a socket"),
    (stat.S_ISCHR, "is a character device"),
    (stat.S_ISBLK, "is a block device"),
)


class RefusedFile(OSError):
    """A file not read: not a regular file, or over its size budget. ``strerror`` says which,
    in words that follow the file's name (``"is a FIFO (named pipe), not a regular file"``)."""

    def __init__(self, path, reason: str):
        super().__init__(0, reason, os.fspath(path))


#: How every reason of a :class:`RefusedFile` ends: the file was not read at all.
NOT_READ = ": not read"


def not_regular(mode: int) -> str | None:
    """Why a file of ``mode`` (``st_mode``) is not read, or None for a regular file."""
    if stat.S_ISREG(mode):
        return None
    kind = next((words for is_kind, words in _KINDS if is_kind(mode)), "is not a regular file")
    return f"{kind}, not a regular file{NOT_READ}"


def open_regular(path, budget: int | None = None, kind: str = "a side file"):
    """The regular file at ``path`` opened for reading bytes (a buffered binary file object).

    Raises :class:`RefusedFile` (an ``OSError``) for a FIFO, socket, device or directory,
    and, with ``budget``, for a file of more than ``budget`` bytes (``kind`` names the budget's
    files in the reason); other ``OSError`` s (missing, no permission) as :func:`open` raises them.
    """
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_BINARY", 0))
    try:
        info = os.fstat(fd)
        reason = not_regular(info.st_mode)
        if reason is None and budget is not None and info.st_size > budget:
            reason = f"is {_size(info.st_size)}, over the {_size(budget)} budget of {kind}{NOT_READ}"
        if reason is not None:
            raise RefusedFile(path, reason)
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular(path, budget: int | None = None, kind: str = "a side file") -> bytes:
    """Every byte of the regular file at ``path`` (see :func:`open_regular`); at most ``budget``
    bytes, :class:`RefusedFile` when the file holds more (also when it grew while read)."""
    with open_regular(path, budget, kind) as fh:
        data = fh.read() if budget is None else fh.read(budget + 1)
    if budget is not None and len(data) > budget:
        raise RefusedFile(path, f"grew past the {_size(budget)} budget of {kind} while read{NOT_READ}")
    return data


def _size(count: int) -> str:
    """``count`` bytes in words: ``'16 MiB'``, ``'7.5 GiB'``, ``'120 bytes'``.

    >>> _size(16 << 20), _size(7_500_000_000), _size(120)
    ('16 MiB', '6.98 GiB', '120 bytes')
    """
    for unit, shift in (("GiB", 30), ("MiB", 20), ("KiB", 10)):
        if count >= 1 << shift:
            return f"{count / (1 << shift):.3g} {unit}"
    return f"{count} bytes"
