"""Chunked reading and tokenizing of line-oriented text meshes (OBJ, OFF, ASCII PLY).

A file is read in chunks of whole lines, so memory stays bounded whatever the
file size; each chunk is split into tokens with one vectorized pass (a token is
a run of bytes that are not whitespace, nor '/' where asked), and every line
knows its first token and its 1-based number in the file.

Bytes that cannot be text end the read as they are read (issue 45), before any
parsing and whatever the file's size: a NUL byte (what a zero-filled file, a
crashed copy or a preallocated download holds), or a line longer than a chunk
that does not open with a statement allowed to be that long (text with no
line breaks), or longer than :data:`MAX_LINE_BYTES`. The error names the
byte offset in the file.
"""

from __future__ import annotations

import mmap
import re
from dataclasses import dataclass

import numpy as np

from ..errors import MeshError
from .numbers import PAD, out_of_range_reason, parse_floats
from .regular import open_regular

#: Bytes read per chunk: large enough that per-chunk overhead (and the GIL it holds,
#: against the other parsing threads) vanishes, small enough that the per-token
#: temporaries stay in cache-friendly sizes. Measured on a 166 MB OBJ on 2 cores:
#: 2 MB parses in 15% less CPU than 512 KB, and 4 MB gains little more.
CHUNK_BYTES = 1 << 21

#: The longest line read, two chunks: a face of some 200,000 ``v/vt/vn`` corners. A longer one is
#: not a mesh's line; parsing it would cost some 45 bytes of temporaries a byte (a 10 MB face line
#: held 470 MB: five times a chunk's), and reading on would hold the file in memory.
MAX_LINE_BYTES = 4 << 20
#: A line this long must open with a statement that may be long (a face of some 3,000 corners);
#: the bound does not depend on the chunk size, so neither does what a file reads as.
LONG_LINE_BYTES = 64 << 10

_NEWLINE, _CR, _SLASH, _HASH, _BACKSLASH = (ord(c) for c in "\n\r/#\\")


@dataclass
class Chunk:
    """Whole lines of a text file.

    buf : (n,) uint8
        :data:`PAD` spaces, the lines (the last one ending with '\\n'), then
        :data:`PAD` spaces more, so that words read around any token stay inside.
    first_line : int
        1-based number of the chunk's first line.
    joined : (j,) int64
        Sorted offsets in ``buf`` of newlines removed by a '\\' continuation.
    offset : int
        Byte offset in the file of the chunk's first line (``buf[PAD]``).
    """

    buf: np.ndarray
    first_line: int
    joined: np.ndarray
    offset: int = 0

    def _bytearray(self) -> bytearray | None:
        """The bytearray ``buf`` views (as :func:`read_chunks` makes it), else None."""
        base = self.buf.base
        base = base.obj if isinstance(base, memoryview) else base  # NumPy 2 keeps a memoryview of it
        return base if isinstance(base, bytearray) else None

    def find(self, word: bytes) -> int:
        """Offset of the first ``word`` (a byte or more) in ``buf`` (-1: none), at C speed."""
        base = self._bytearray()
        if base is not None:
            return base.find(word, 0, len(self.buf))
        if len(word) > 1:
            return self.buf.tobytes().find(word)
        hits = np.flatnonzero(self.buf == word[0])
        return int(hits[0]) if len(hits) else -1


class Mapped(mmap.mmap):
    """A read-only file map with the bytes methods the readers of a source use (``mmap`` lacks ``count``)."""

    def count(self, sub: bytes, start: int = 0, end: int | None = None) -> int:
        with memoryview(self) as view:
            return bytes(view[start:end]).count(sub)


def mapped_file(path) -> Mapped | None:
    """The bytes of the file at ``path`` as a read-only memory map (the page cache's own pages:
    no copy, no fresh memory to fault in), or None where the file cannot be mapped (empty, not
    a regular file, unreadable: :func:`affinity.loaders.read_source` then reads it, or says why not).

    A map shows the file as it is while it is read: a file truncated meanwhile ends the
    process (SIGBUS) instead of reading short; a check reads a file once, right after mapping it.
    A file whose first bytes hold a NUL (zero-filled) is mapped page by page as read, not
    whole: its reader stops in the first chunk.
    """
    try:
        with open_regular(path) as fh:
            text = b"\0" not in fh.read(1 << 16)
            if text and hasattr(mmap, "MAP_POPULATE"):  # Linux: every page mapped in one call, not one fault each
                return Mapped(fh.fileno(), 0, flags=mmap.MAP_SHARED | mmap.MAP_POPULATE, prot=mmap.PROT_READ)
            return Mapped(fh.fileno(), 0, access=mmap.ACCESS_READ)
    except (OSError, ValueError):
        return None


class BufferReader:
    """``readinto`` and ``tell`` over a bytes-like buffer, for :func:`read_chunks` (``io.BytesIO``
    copies any buffer but ``bytes`` whole first)."""

    def __init__(self, data):
        self.view = memoryview(data)
        self.offset = 0

    def tell(self) -> int:
        return self.offset

    def readinto(self, into) -> int:
        count = min(len(into), len(self.view) - self.offset)
        into[:count] = self.view[self.offset : self.offset + count]
        self.offset += count
        return count


class NotText(MeshError):
    """Bytes that cannot be a text mesh, found while reading (see the module docstring).

    ``offset`` is the byte offset in the file; ``line`` is 0 when the reader does
    not count lines (the caller knows the lines of the chunks it was given).
    """

    def __init__(self, path, line: int, offset: int, what: str, hint: str = ""):
        super().__init__(path, line, f"{what} at offset {offset:,}: not a text mesh{hint}")
        self.offset = offset


def read_chunks(fh, path, first_line: int = 1, continuations: bool = False, size: int | None = None,
                count_lines: bool = True, long_line: re.Pattern | None = None):
    """Yield :class:`Chunk` s of whole lines from the binary file object ``fh`` (``readinto``, ``tell``).

    With ``continuations`` a '\\' right before a line break joins the two lines
    (the backslash and the break become spaces, so byte offsets and line
    numbers still point into the file). The last line gets a '\\n' if it lacks one.
    Without ``count_lines`` every chunk's lines count from ``first_line`` (the
    caller adds the lines of the chunks before; counting them here would cost
    a pass over every chunk on the reading thread). ``size`` defaults to
    :data:`CHUNK_BYTES`, read at call time (tests shrink it).

    Raises :class:`NotText` (naming ``path``) as soon as the bytes read hold a NUL, or
    a line runs past a chunk and :data:`LONG_LINE_BYTES` without ``long_line`` matching
    its start (only statements ``long_line`` names may be that long: faces), or past
    :data:`MAX_LINE_BYTES`. The whole lines before the bad byte are
    yielded first, so a parse error earlier in the file is found first. Time and
    memory are those of the bytes read up to there: a long line is read in blocks
    that double, never copied more than twice over.
    """
    size = CHUNK_BYTES if size is None else size
    offset = fh.tell()  # of the first byte of ``carry`` in the file
    carry = b""
    line = first_line
    while True:
        head = PAD + len(carry)
        block = max(size, len(carry))  # a long line: double the read, linear in the line's length
        buf = bytearray(head + block + PAD)
        buf[:PAD] = b" " * PAD
        buf[PAD:head] = carry
        end = head + fh.readinto(memoryview(buf)[head : head + block])
        nul = buf.find(b"\0", head, end)
        if nul >= 0:
            end = buf.rfind(b"\n", PAD, nul) + 1 or PAD  # the whole lines before it are read
            bad_line = line + buf.count(b"\n", PAD, end) if count_lines else 0
            error = NotText(path, bad_line, offset + nul - PAD, "binary data (byte 0x00)",
                            " (a zero-filled or damaged file?)")
        if end == head or nul >= 0:  # end of file, or of its text
            if end == PAD:
                if nul >= 0:
                    raise error
                return
            if nul < 0:
                buf[end : end + 1] = b"\n"
            cut = end + (nul < 0)
        else:
            cut = _last_line_break(buf, end, continuations)
            if cut == 0:  # one line longer than the chunk: read on, if the format has such lines
                _check_long_line(buf, end, path, line if count_lines else 0, offset, long_line)
                carry = bytes(buf[PAD:end])
                continue
        carry = bytes(buf[cut:end])
        buf[cut : cut + PAD] = b" " * PAD
        array = np.frombuffer(buf, dtype=np.uint8, count=cut + PAD)
        joined = np.zeros(0, np.int64)
        if continuations and buf.find(b"\\", PAD, cut) >= 0:
            joined = _join_continuations(array, cut - 1)
        yield Chunk(array, line, joined, offset)
        if nul >= 0:
            raise error
        offset += cut - PAD
        if count_lines:
            line += buf.count(b"\n", PAD, cut) + len(joined)


def _check_long_line(buf: bytearray, end: int, path, line: int, offset: int, long_line: re.Pattern | None) -> None:
    """NotText unless the line ``buf[PAD:end]`` (no line break in it) may be read on."""
    if end - PAD > MAX_LINE_BYTES:
        raise NotText(path, line, offset, f"a line longer than {MAX_LINE_BYTES >> 20} MiB")
    if end - PAD < LONG_LINE_BYTES:
        return
    if long_line is None or not long_line.match(buf, PAD, end):
        raise NotText(path, line, offset, f"{end - PAD:,} bytes with no line break and no statement")


def _last_line_break(buf: bytearray, end: int, continuations: bool) -> int:
    """Offset just past the last '\\n' before ``end`` that ends a statement (0: none)."""
    cut = buf.rfind(b"\n", PAD, end) + 1
    while continuations and cut and _continued(buf, cut - 1):
        cut = buf.rfind(b"\n", PAD, cut - 1) + 1
    return cut


def _continued(buf: bytearray, newline: int) -> bool:
    """The line break at ``newline`` follows a '\\' (optionally with '\\r' between)."""
    before = newline - 1 - (buf[newline - 1] == _CR)
    return before >= PAD and buf[before] == _BACKSLASH


def _join_continuations(buf: np.ndarray, last: int) -> np.ndarray:
    """Blank out '\\' + line break in place; return the removed newlines' offsets.

    ``last`` is the offset of the chunk's last line break: a '\\' before it
    (the end of the file) joins nothing: it is blanked and the break kept.
    """
    slash = np.flatnonzero(buf[:last] == _BACKSLASH)
    crlf = (buf[slash + 1] == _CR) & (buf[np.minimum(slash + 2, last)] == _NEWLINE)
    newline = np.where(crlf, slash + 2, slash + 1)
    hit = buf[newline] == _NEWLINE
    joined = hit & (newline < last)
    for offset in (0, 1, 2):
        blank = slash[hit & (offset <= newline - slash - (~joined))] + offset
        buf[blank] = ord(" ")
    return newline[joined]


def find_word(data, word: bytes, anchor: int, start: int = 0) -> int:
    """Offset of the first ``word`` in the bytes-like ``data`` at or after ``start`` (-1: none).

    ``word[anchor]`` is a byte mesh data seldom holds (no digit, sign, dot, space or
    keyword letter: the ':' of ``affinity:``, the 'b' of ``mtllib``): the search jumps
    between its occurrences with a one-byte find (``memchr``, several times faster
    than a multi-byte find over a big file) and checks the word around each; past
    a few dozen false hits it hands over to the plain find.
    """
    byte = word[anchor : anchor + 1]
    at = data.find(byte, start + anchor)
    for _ in range(64):
        if at < 0:
            return -1
        if data[at - anchor : at - anchor + len(word)] == word:
            return at - anchor
        at = data.find(byte, at + 1)
    return -1 if at < 0 else data.find(word, at - anchor)


class _Ragged:
    """Rows stored as offsets ``first`` (R + 1,) into a flat array."""

    first: np.ndarray

    @property
    def counts(self) -> np.ndarray:
        """(R,) int64 items per row."""
        return np.diff(self.first)


@dataclass
class Tokens(_Ragged):
    """The tokens and lines of one :class:`Chunk`.

    starts, ends : (K,) int64
        Byte offsets of every token in ``buf`` (comments already removed).
    first : (L + 1,) int64
        Index of the first token of every line; line ``i`` owns tokens
        ``first[i]:first[i + 1]``.
    number : (L,) int64
        1-based line number in the file of every line.
    begin, end : (L,) int64
        Byte offsets of every line's first byte and of its '\\n'.
    slashes : int
        Number of '/' bytes in the chunk (counted when they separate tokens, else 0).
    """

    buf: np.ndarray
    starts: np.ndarray
    ends: np.ndarray
    first: np.ndarray
    number: np.ndarray
    begin: np.ndarray
    end: np.ndarray
    slashes: int = 0

    def line_of_byte(self, offset) -> int:
        return int(self.number[np.searchsorted(self.end, offset)])

    def line_of_token(self, token) -> int:
        return int(self.number[np.searchsorted(self.first, token, side="right") - 1])

    def text(self, token) -> str:
        return bytes(self.buf[self.starts[token] : self.ends[token]]).decode("utf-8", "backslashreplace")


def tokenize(chunk: Chunk, path, slash: bool = False) -> Tokens:
    """Split a chunk into tokens at whitespace (and '/' when ``slash``).

    A token starting with '#' comments out the rest of its line. Control bytes
    other than tab, line feed, vertical tab, form feed and carriage return mean
    the file is not text: :class:`MeshError` naming their line.
    """
    buf = chunk.buf
    low = np.flatnonzero(buf < 32)  # the line breaks, and any other control byte
    end = low if (buf[low] == _NEWLINE).all() else low[buf[low] == _NEWLINE]
    begin = np.empty_like(end)
    begin[:1] = PAD
    np.add(end[:-1], 1, out=begin[1:])
    number = np.arange(chunk.first_line, chunk.first_line + len(end))
    if len(chunk.joined):
        number += np.searchsorted(chunk.joined, begin)
    separator = buf <= 32
    slashes = 0
    if slash:
        is_slash = buf == _SLASH
        slashes = int(np.count_nonzero(is_slash))
        separator |= is_slash
    # Token edges alternate start, end: the buffer starts and ends with spaces.
    edges = np.flatnonzero(separator[1:] != separator[:-1])
    edges += 1
    starts, ends = edges[0::2], edges[1::2]
    tokens = Tokens(buf, starts, ends, np.zeros(0, np.int64), number, begin, end, slashes)
    if len(low) != len(end) or chunk.find(b"\x7f") >= 0:
        _reject_control_bytes(tokens, low, path)
    first = np.empty(len(begin) + 1, dtype=np.int64)
    if chunk.find(b"#") >= 0:
        tokens.starts, tokens.ends = _drop_comments(buf, starts, ends, end)
        first[:-1] = np.searchsorted(tokens.starts, begin)
    else:  # no token spans a line break: 2 * (tokens before a line) edges precede it
        np.right_shift(np.searchsorted(edges, begin), 1, out=first[:-1])
    first[-1] = len(tokens.starts)
    tokens.first = first
    return tokens


def _reject_control_bytes(tokens: Tokens, low: np.ndarray, path) -> None:
    """MeshError at the first byte below 32 (offsets ``low``) other than tab, line
    feed, vertical tab, form feed and carriage return, or DEL (127)."""
    text = tokens.buf
    control = low[text[low] - np.uint8(9) > 4]
    delete = np.flatnonzero(text == 127)
    offsets = np.concatenate([control[:1], delete[:1]])
    if len(offsets):
        offset = int(offsets.min())
        byte = int(tokens.buf[offset])
        raise MeshError(path, tokens.line_of_byte(offset), f"binary data (byte 0x{byte:02x}): not a text mesh")


def _drop_comments(buf, starts, ends, line_end):
    """Remove every token from one starting with '#' to the end of its line."""
    hashes = np.flatnonzero(buf[starts] == _HASH)
    if len(hashes) == 0:
        return starts, ends
    stop = np.searchsorted(starts, line_end[np.searchsorted(line_end, starts[hashes])])
    depth = np.zeros(len(starts) + 1, dtype=np.int32)
    np.add.at(depth, hashes, 1)
    np.add.at(depth, stop, -1)
    keep = np.cumsum(depth[:-1]) == 0
    return starts[keep], ends[keep]


def floats_or_raise(tokens: Tokens, path, which: np.ndarray, finite: bool = False) -> np.ndarray:
    """(n,) float64 values of the tokens ``which``; MeshError on the first that is
    not a number (or, with ``finite``, not a finite one within :data:`~.numbers.LARGEST`)."""
    values, bad = parse_floats(tokens.buf, tokens.starts[which], tokens.ends[which], finite)
    if len(bad):
        token = which[bad[0]]
        value = values[bad[0]]
        if np.isfinite(value):
            raise MeshError(path, tokens.line_of_token(token), out_of_range_reason(tokens.text(token)))
        kind = "a number" if np.isnan(value) and "nan" not in tokens.text(token).lower() else "a finite number"
        raise MeshError(path, tokens.line_of_token(token), f"not {kind}: {tokens.text(token)!r}")
    return values


@dataclass
class Rows(_Ragged):
    """Every non-empty line of a text section as a row of numbers.

    number : (R,) int64
        1-based line number of every row.
    first : (R + 1,) int64
        Row ``r`` owns ``values[first[r]:first[r + 1]]``.
    values : (T,) float64
    """

    number: np.ndarray
    first: np.ndarray
    values: np.ndarray


#: A row of numbers (or a comment) may run longer than a chunk: a face of many corners.
_LONG_ROW = re.compile(rb"\s*[-+.0-9#]")


def read_rows(fh, path, first_line: int) -> Rows:
    """Read the rest of ``fh`` as rows of whitespace-separated numbers ('#' comments allowed)."""
    numbers, counts, values = [], [], []
    for chunk in read_chunks(fh, path, first_line, long_line=_LONG_ROW):
        tokens = tokenize(chunk, path)
        per_line = tokens.counts
        numbers.append(tokens.number[per_line > 0])
        counts.append(per_line[per_line > 0])
        values.append(floats_or_raise(tokens, path, np.arange(len(tokens.starts))))
    counts = np.concatenate(counts) if counts else np.zeros(0, np.int64)
    return Rows(
        number=np.concatenate(numbers) if numbers else np.zeros(0, np.int64),
        first=np.concatenate(([0], np.cumsum(counts))),
        values=np.concatenate(values) if values else np.zeros(0),
    )
