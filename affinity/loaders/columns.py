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

Rows are copied into a zero-padded matrix whose width is a multiple of 8, with
8 spare bytes before each row, so that each row is a run of aligned ``uint64``
words. Once XORed with the first row's bytes (``'0'`` at its digits), the
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
_FRONT = 8  # spare bytes before each row: a word ending at a row's first digits stays inside it
_DIGITS = np.zeros(256, dtype=bool)
_DIGITS[ord("0") : ord("9") + 1] = True


@dataclass
class Group:
    """Lines laid out like their first.

    rows : (n,) int64
        Indices of the lines (ascending) among those passed to :func:`alike_groups`.
    first : bytes
        The first line, its line break included.
    digits : (n, W) uint64
        The rows as words: digit values 0..9 where the first line has a digit, 0 elsewhere;
        byte ``k`` of a line is byte ``(k + 8) % 8`` of word ``(k + 8) // 8``.
    """

    rows: np.ndarray
    first: bytes
    digits: np.ndarray

    def numbers(self, spans, dots=None) -> np.ndarray:
        """(n, S) uint64 value of the digits in each span ``spans[s] = (start, end)``
        (byte offsets in the line, at most 8 bytes) but the one at ``dots[s]`` (-1: none),
        a decimal point."""
        end = np.array([e for _, e in spans], dtype=np.int64) + _FRONT
        length = (end - _FRONT - np.array([s for s, _ in spans], dtype=np.int64)).astype(np.uint64)
        start = end - 8  # the word of the 8 bytes ending at the span's end
        word = start >> 3
        shift = (start & 7).astype(np.uint64) << _U(3)
        low = self.digits[:, word]
        low >>= shift
        high = self.digits[:, word + 1]
        high <<= _U(64) - shift  # a shift by 64 gives 0 in NumPy
        low |= high
        low &= _ONES << (_U(8) * (_U(8) - length))  # the span's bytes only
        if dots is not None:  # the digits before the point move up into its (zero) byte
            at = (np.asarray(dots) + _FRONT - start).astype(np.uint64)
            below = np.where(np.asarray(dots) >= 0, (_U(1) << (_U(8) * at)) - _U(1), _U(0))
            before = low & below
            low ^= before
            before <<= _U(8)
            low |= before
        return eight_digits(low)


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
        padded = -(-(width + _FRONT) // 8) * 8 + 8  # and a spare word after the row
        window = np.lib.stride_tricks.sliding_window_view(buf, width)
        while len(rows):
            if len(groups) == limit:
                return None
            first = bytes(buf[begin[rows[0]] : begin[rows[0]] + width])
            matrix = np.zeros((len(rows), padded), np.uint8)
            consecutive = rows[-1] - rows[0] + 1 == len(rows)
            if consecutive and begin[rows[-1]] - begin[rows[0]] == width * (len(rows) - 1):
                start = begin[rows[0]]
                matrix[:, _FRONT : _FRONT + width] = buf[start : start + width * len(rows)].reshape(-1, width)
            else:
                matrix[:, _FRONT : _FRONT + width] = window[begin[rows]]
            words = matrix.view("<u8")
            expected, sixes, checked = _row_masks(first, padded)
            words ^= expected
            bad = words + sixes
            bad |= words
            bad &= checked
            if bad.max() == 0:
                groups.append(Group(rows, first, words))
                break
            alike = ~np.bitwise_or.reduce(bad, axis=1).astype(bool)
            if alike.all():
                groups.append(Group(rows, first, words))
                break
            groups.append(Group(rows[alike], first, words[alike]))
            rows = rows[~alike]
    return groups


def _row_masks(first: bytes, padded: int):
    """(W,) uint64 words for the first row: the bytes to XOR away (``'0'`` at the digits),
    the ``+6`` of the digit test at the digits, and the bits that must be 0 afterwards."""
    row = np.frombuffer(first, np.uint8)
    digit = _DIGITS[row]
    expected = np.zeros(padded, np.uint8)
    expected[_FRONT : _FRONT + len(row)] = np.where(digit, ord("0"), row)
    sixes = np.zeros(padded, np.uint8)
    sixes[_FRONT : _FRONT + len(row)][digit] = 6
    checked = np.full(padded, 0xFF, np.uint8)
    checked[_FRONT : _FRONT + len(row)][digit] = 0xF0
    return expected.view("<u8"), sixes.view("<u8"), checked.view("<u8")
