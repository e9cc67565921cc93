"""Side files (material libraries, textures) read once: one open a file, the same bytes for every reader.

One check reads a texture's header for the texel unit, for Q902 and against the decode budget, then decodes
it for the visible reading; a material library is read by the OBJ reader, the resource tree and Q902. Each
reads through :func:`read_side_file` or :func:`open_side_file`, which open a file once while it is
unchanged (its path, size, modification time and inode, from ``stat``, which opens nothing) and hand every
caller the same bytes, so they agree on what the file says. A file that cannot be kept (missing, not a
regular file, over the caller's budget or over :data:`KEPT_FILE`) is opened as before, each time, and says
why in the same words (:mod:`.regular`). The bytes are kept for one file's check: :func:`forget` drops them
when it ends (:func:`affinity.pipeline.check.load_and_check`), so a run over many files holds one file's.
"""

from __future__ import annotations

import io
import os
import stat
import threading
from collections import OrderedDict

from .regular import open_regular, read_regular

#: A file of more bytes is never kept (a texture too big to decode: its header is read in part, each time).
KEPT_FILE = 32 << 20
#: Bytes kept over all files; the least recently read go first.
KEPT_BYTES = 64 << 20

_kept: OrderedDict[tuple, bytes] = OrderedDict()
_lock = threading.Lock()  # one reader at a time: two threads asking for one file open it once


def kept_bytes(path, budget: int | None = None) -> bytes | None:
    """Every byte of the regular file at ``path``, read once while it is unchanged; None where it is not
    kept: missing, not a regular file, over ``budget`` or :data:`KEPT_FILE` bytes (the caller opens it and
    meets the reason)."""
    try:
        info = os.stat(path)
    except (OSError, ValueError):
        return None
    if not stat.S_ISREG(info.st_mode) or info.st_size > min(KEPT_FILE, KEPT_FILE if budget is None else budget):
        return None
    key = (os.path.realpath(path), info.st_size, info.st_mtime_ns, info.st_ino)
    with _lock:
        data = _kept.get(key)
        if data is None:
            try:
                data = read_regular(path, info.st_size)
            except OSError:
                return None
            _kept[key] = data
            while sum(map(len, _kept.values())) > KEPT_BYTES and len(_kept) > 1:
                _kept.popitem(last=False)
        _kept.move_to_end(key)
        return data


def read_side_file(path, budget: int | None = None) -> bytes:
    """:func:`~.regular.read_regular`, served from the bytes read once (:func:`kept_bytes`)."""
    data = kept_bytes(path, budget)
    return read_regular(path, budget) if data is None else data


def open_side_file(path, budget: int | None = None):
    """:func:`~.regular.open_regular`, served from the bytes read once (:func:`kept_bytes`): a binary file
    object either way."""
    data = kept_bytes(path, budget)
    return open_regular(path, budget) if data is None else io.BytesIO(data)


def forget() -> None:
    """Drop every kept file's bytes (the end of one file's check)."""
    with _lock:
        _kept.clear()
