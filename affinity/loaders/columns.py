"""Lines laid out alike, read as columns of bytes.

Two lines are laid out alike when they have the same length and, byte for
byte, either the same byte or two digits. Then every token of one is a token
of the other at the same offsets, and the lines of a group are rows of one
``(n, width)`` byte matrix whose digit columns are known from its first row:
no tokenizing, and every number is read with word arithmetic whose shifts and
masks are constants of the group (:mod:`affinity.loaders.numbers` reads each
token's word at offsets of its own). Exported meshes are mostly such groups
(``%.6f`` coordinates, ``v/vt/vn`` faces of consecutive indices); what is not
is the token reader's job.

Each line is read as ``uint64`` words, word ``k`` of every line in one array
(a strided view of the buffer when the lines follow each other), so that every
operation runs along the lines. Once XORed with the first row's bytes (``'0'`` at its digits), the
bytes of a row that is laid out alike are 0 outside the digits and digit
values 0..9 in them: one check per word (the ``+6`` digit test of
:mod:`affinity.loaders.numbers` at the digits, an exact 0 elsewhere).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .numbers import eight_digits

_U = np.uint64
_ONES = _U((1 << 64) - 1)
_DIGITS = np.zeros(256, dtype=bool)
_DIGITS[ord("0") : ord("9") + 1] = True


@dataclass
class Group:
    """Lines laid out like their first.

    rows : (n,) int64
        Indices of the lines (ascending) among those passed to :func:`alike_groups`.
    first : bytes
        The first line, its line break included.
    digits : (W, n) uint64
        Lines as words, word by word (every operation runs along the lines):
        digit values 0..9 where the first line has a digit, 0 elsewhere; byte
        ``k`` of a line is byte ``k % 8`` of its word ``k // 8`` (the last word's bytes past
        the line are another line's, and ignored).
    """

    rows: np.ndarray
    first: bytes
    digits: np.ndarray

    def numbers(self, spans, dots=None) -> np.ndarray:
        """(S, n) uint64 value of the digits in each span ``spans[s] = (start, end)``
        (byte offsets in the line, at most 8 bytes) but the one at ``dots[s]`` (-1: none),
        a decimal point."""
        return eight_digits(self.windows(spans, dots))

    def windows(self, spans, dots=None) -> np.ndarray:
        """(S, n) uint64 digit values of each span as :meth:`numbers` reads them (the
        span's last digit in the highest byte, 0 bytes before its first): equal
        windows are equal numbers."""
        end = np.array([e for _, e in spans], dtype=np.int64)
        length = (end - np.array([s for s, _ in spans], dtype=np.int64)).astype(np.uint64)
        # The 8 bytes ending at the span's end, from two words; before a line's first
        # word (word -1: its last) are bytes the mask drops.
        start = end - 8
        word = start >> 3
        shift = ((start & 7).astype(np.uint64) << _U(3))[:, None]
        low = self.digits.take(word, axis=0)
        low >>= shift
        high = self.digits.take(np.minimum(word + 1, len(self.digits) - 1), axis=0)  # unused when aligned
        high <<= _U(64) - shift  # a shift by 64 gives 0 in NumPy
        low |= high
        low &= (_ONES << (_U(8) * (_U(8) - length)))[:, None]  # the span's bytes only
        if dots is not None and max(dots) >= 0:  # the digits before the point move up into its (zero) byte
            at = (np.asarray(dots) - start).astype(np.uint64)
            below = np.where(np.asarray(dots) >= 0, (_U(1) << (_U(8) * at)) - _U(1), _U(0))[:, None]
            before = low & below
            low ^= before
            before <<= _U(8)
            low |= before
        return low


def alike_groups(buf: np.ndarray, begin: np.ndarray, end: np.ndarray, limit: int) -> list[Group] | None:
    """Split lines into groups laid out alike (:class:`Group`); None past ``limit`` groups.

    buf : (N,) uint8; begin, end : (L,) int64 offsets of every line's first byte and its line break.
    """
    length = end - begin + 1
    groups: list[Group] = []
    order = np.argsort(length, kind="stable")
    cuts = np.flatnonzero(np.diff(length[order])) + 1
    for rows in np.split(order, cuts):
        width = int(length[rows[0]])
        words = _line_words(buf, begin[rows], width)
        masks = None
        while len(rows):
            if len(groups) == limit:
                return None
            first = bytes(buf[begin[rows[0]] : begin[rows[0]] + width])
            previous, masks = masks, _row_masks(first, len(words))
            expected, sixes, checked = masks
            words ^= expected if previous is None else expected ^ previous[0]
            bad = words + sixes
            bad |= words
            bad &= checked
            if bad.max() == 0:
                groups.append(Group(rows, first, words))
                break
            alike = np.bitwise_or.reduce(bad, axis=0) == 0
            groups.append(Group(rows[alike], first, words.take(np.flatnonzero(alike), axis=1)))
            rest = np.flatnonzero(~alike)
            rows, words = rows[rest], words.take(rest, axis=1)  # take: several times faster than a mask
    return groups


def _line_words(buf: np.ndarray, begin: np.ndarray, width: int) -> np.ndarray:
    """(W, n) uint64: word ``k`` of each line of ``width`` bytes starting at ``begin`` (n,),
    the bytes ``begin + 8k ..`` (the last word runs into the next line: masks ignore that)."""
    count = -(-width // 8)
    words = np.empty((count, len(begin)), np.uint64)
    if begin[-1] - begin[0] == width * (len(begin) - 1):  # consecutive lines: a strided view
        for k in range(count):
            words[k] = np.ndarray((len(begin),), "<u8", buffer=buf, offset=int(begin[0]) + 8 * k, strides=(width,))
    else:  # word k from aligned words k and k + 1 of each line's start, all shifted alike
        offset = -buf.ctypes.data % 8
        aligned = buf[offset : offset + 8 * ((len(buf) - offset) // 8)].view("<u8")
        start = begin - offset
        index = start >> 3
        shift = (start & 7).astype(np.uint64) << _U(3)
        back = _U(64) - shift  # a shift by 64 gives 0 in NumPy
        following = aligned.take(index, mode="clip")
        for k in range(count):
            word = following
            following = aligned.take(index + (k + 1), mode="clip")  # clip: past the buffer only past the line
            np.right_shift(word, shift, out=words[k])
            word = following << back
            words[k] |= word
    return words


def _row_masks(first: bytes, count: int):
    """(W, 1) uint64 words for the first row: the bytes to XOR away (``'0'`` at the digits),
    the ``+6`` of the digit test at the digits, and the bits that must be 0 afterwards."""
    row = np.frombuffer(first, np.uint8)
    digit = _DIGITS[row]
    expected = np.zeros(8 * count, np.uint8)
    expected[: len(row)] = np.where(digit, ord("0"), row)
    sixes = np.zeros(8 * count, np.uint8)
    sixes[: len(row)][digit] = 6
    checked = np.zeros(8 * count, np.uint8)  # the bytes after the line are not checked
    checked[: len(row)] = np.where(digit, 0xF0, 0xFF)
    return tuple(mask.view("<u8")[:, None] for mask in (expected, sixes, checked))
