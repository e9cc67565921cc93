"""Rows of text built many at a time in a byte grid, for the formats that write one row per finding.

A format's rows for one rule share most of their text (keys, the rule's code,
name and message) and differ in a few fields (line, face, value, level). Row i
of the text is laid out in row i of an (n, W) uint8 grid: each constant piece
broadcast into its columns, each field in a slot as wide as its widest entry,
shorter entries padded with NUL bytes. The grid's bytes without the NULs are the
rows, one after the other. The formats never write a NUL (JSON escapes it, XML
cannot carry it and gets U+FFFD, text lines quote it), so only padding is
dropped. Numbers are converted a column at a time: integers digit by digit in
NumPy, floats with one ``%`` over a joined template (``%r`` is JSON's float
text, ``%.4g`` the text lines'). Time and memory grow with the findings, with
small constants and no Python step per finding.

>>> assemble([b"face ", integers(np.array([7, 12, -3])), b": ", floats([0.5, 1e-7, 2.0], "%r"), b"\\n"])
'face 7: 0.5\\nface 12: 1e-07\\nface -3: 2.0\\n'
"""

from __future__ import annotations

import functools
import sys
from collections.abc import Sequence

import numpy as np

#: A piece of every row: the same bytes in each, or an (n, w) uint8 field, NUL-padded.
Piece = bytes | np.ndarray


def integers(numbers: np.ndarray) -> np.ndarray:
    """(n, w) uint8: each of ``numbers`` (n,) int as ``%d`` writes it, right-aligned in a NUL-padded slot (one
    number throughout, a column of 1s, converted once)."""
    numbers = np.asarray(numbers, dtype=np.int64)
    if len(numbers) and numbers.min() == numbers.max():
        one = np.frombuffer(b"%d" % numbers[0], dtype=np.uint8)
        return np.broadcast_to(one, (len(numbers), len(one)))
    magnitude = np.abs(numbers)
    largest = int(magnitude.max(initial=0))
    width = len(str(largest))
    digits = np.empty((len(numbers), width), dtype=np.uint8)
    rest = magnitude.astype(np.uint32 if largest < 2**32 else np.uint64)  # 32-bit division: twice as fast
    ten = rest.dtype.type(10)
    for place in range(width - 1, -1, -1):  # a loop over digit places, each a column at once
        quotient = rest // ten
        digits[:, place] = rest - quotient * ten
        rest = quotient
    digits += ord("0")
    digits[:, :-1][magnitude[:, None] < 10 ** np.arange(width - 1, 0, -1)] = 0  # leading zeros (0 keeps its digit)
    if not (numbers < 0).any():
        return digits
    sign = np.where(numbers < 0, ord("-"), 0).astype(np.uint8)[:, None]
    return np.hstack([sign, digits])


def formatted(values: Sequence, spec: str) -> np.ndarray:
    """(n, w) uint8: each of ``values`` (n,) as ``spec % value`` writes it (``"%s"`` for texts), converted in
    one ``%`` over a joined template, left-aligned in a NUL-padded slot. The texts must hold no NUL."""
    return padded(((spec + "\0") * len(values) % tuple(values)).encode(), len(values))


def floats(values: Sequence[float], spec: str) -> np.ndarray:
    """(n, w) uint8: each of ``values`` (n,) float as ``spec`` (``"%r"``, ``"%.4g"``) writes it, NUL-padded:
    formatted in one ``%`` at the widest a float can take (the most negative double's text), so the slots
    need no searching; the columns no value reaches are dropped."""
    width = len(spec % -sys.float_info.max)
    text = (f"%-{width}{spec[1:]}" * len(values) % tuple(values)).replace(" ", "\0").encode()
    laid = np.frombuffer(text, dtype=np.uint8).reshape(len(values), width)
    return laid[:, : int(np.flatnonzero(laid.any(axis=0)).max(initial=-1)) + 1]


def padded(joined: bytes, n: int) -> np.ndarray:
    """(n, w) uint8: the ``n`` entries of ``joined``, each ended by a NUL, left-aligned in NUL-padded rows."""
    if n == 0:
        return np.zeros((0, 0), dtype=np.uint8)
    flat = np.frombuffer(joined, dtype=np.uint8)
    kept = flat != 0
    lengths = np.diff(np.flatnonzero(~kept), prepend=-1) - 1  # (n,)
    laid = np.zeros((n, int(lengths.max(initial=0))), dtype=np.uint8)
    laid[np.arange(laid.shape[1]) < lengths[:, None]] = flat[kept]  # row by row, as the entries follow
    return laid


def choice(index: np.ndarray, options: Sequence[str]) -> np.ndarray:
    """(n, w) uint8: ``options[index[i]]`` for each i (``index`` (n,) int), each option encoded once."""
    return _options(tuple(options))[np.asarray(index, dtype=np.intp)]


@functools.lru_cache(maxsize=64)
def _options(options: tuple[str, ...]) -> np.ndarray:
    """(k, w) uint8: the options of :func:`choice`, laid out once for every block that picks from them."""
    return formatted(options, "%s")


def grid(pieces: Sequence[Piece], n: int) -> np.ndarray:
    """(n, W) uint8: ``n`` rows laid out from ``pieces`` (constant bytes or (n, w) fields), NUL-padded."""
    widths = [len(p) if isinstance(p, bytes) else p.shape[1] for p in pieces]
    rows = np.empty((n, sum(widths)), dtype=np.uint8)
    at = 0
    for piece, width in zip(pieces, widths):
        rows[:, at : at + width] = np.frombuffer(piece, dtype=np.uint8) if isinstance(piece, bytes) else piece
        at += width
    return rows


def text(rows: np.ndarray) -> str:
    """The text of a grid of rows (:func:`grid`): its bytes without the NUL padding, decoded as UTF-8. (A
    mask takes the same time however many NULs there are; ``bytes.replace`` takes a step per NUL, and a
    JUnit case that does not fail pads its opening by some 90: 86 -> 72 ms on the car's JUnit.)"""
    return rows[rows != 0].tobytes().decode("utf-8")


def assemble(pieces: Sequence[Piece]) -> str:
    """The rows laid out from ``pieces`` (:func:`grid`; their count from the first field), as one text."""
    n = next((len(p) for p in pieces if not isinstance(p, bytes)), 1)
    return text(grid(pieces, n))
