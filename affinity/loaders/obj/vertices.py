"""The vertex tables of the OBJ reader: the numbers of the ``v``, ``vt`` and ``vn`` lines of a chunk."""

from __future__ import annotations

import numpy as np

from ...errors import MeshError
from ..faces import ragged_positions
from ..numbers import parse_floats
from ..text import Tokens, floats_or_raise
from .scan import SLASH, WIDTHS, V, line_tokens, token_block

_MAX_WIDTH = 8
#: ``_ALLOWED[kind][min(n, 8)]``: a line of that kind may carry ``n`` numbers.
_ALLOWED = {kind: np.isin(np.arange(_MAX_WIDTH + 1), widths) for kind, widths in WIDTHS.items()}


def element_rows(tokens: Tokens, path, lines, which, nan_colors: list, fast: bool) -> np.ndarray:
    """(n, width) float64 numbers of the ``which`` lines, NaN where a line has fewer.

    NaN colours (``v x y z r g b`` lines) are kept and counted in ``nan_colors``
    (see :func:`_nan_colors_or_raise`); every other number must be finite. Lines that all
    carry the same allowed number of tokens are one (lines, numbers) block (the fast path;
    not with ``fast=False``), any others are read token by token: the same rows and errors.
    """
    if len(lines) == 0:
        return np.zeros((0, WIDTHS[which][0]))
    counts = tokens.counts[lines]
    if fast and counts.min() == counts.max() and _ALLOWED[which][min(counts[0] - 1, _MAX_WIDTH)]:
        width = int(counts[0]) - 1  # one width: a (lines, numbers) block
        starts, ends = token_block(tokens, lines, width)
        rows, bad = parse_floats(tokens.buf, starts, ends, finite=True)
        if len(bad):
            line, column = bad // width, bad % width
            token = tokens.first[lines[line]] + 1 + column
            _nan_colors_or_raise(tokens, path, which, token, column, width, nan_colors)
    else:
        width, numbers = line_tokens(tokens, lines)
        wrong = ~_ALLOWED[which][np.minimum(width, _MAX_WIDTH)]
        if wrong.any():
            line = lines[np.argmax(wrong)]
            raise MeshError(path, tokens.number[line],
                            f"{tokens.text(tokens.first[line])} line with {width[wrong][0]} numbers")
        values, bad = parse_floats(tokens.buf, tokens.starts[numbers], tokens.ends[numbers], finite=True)
        if len(bad):
            line = np.repeat(np.arange(len(width)), width)[bad]
            column = ragged_positions(np.zeros(len(width), np.int64), width)[bad]
            _nan_colors_or_raise(tokens, path, which, numbers[bad], column, width[line], nan_colors)
        # As wide as the widest line: 'v x y z' among 'v x y z w' lines has no colour.
        rows = np.full((len(width), max(int(width.max()), WIDTHS[which][0])), np.nan)
        rows[np.repeat(np.arange(len(width)), width), ragged_positions(np.zeros(len(width), np.int64), width)] = values
    if which != V or rows.shape[1] == 3:
        return rows
    if rows.shape[1] == 4:  # 'v x y z w': w is not a colour
        return rows[:, :3]
    if rows.shape[1] == 7:
        rows[np.isnan(rows[:, 4]), 3] = np.nan  # 'v x y z w' among colour lines
    return rows[:, :6]  # the alpha of 'v x y z r g b a' is not kept


def _nan_colors_or_raise(tokens: Tokens, path, which, token, column, width, nan_colors: list) -> None:
    """Of the tokens ``token`` (n,) that are not finite numbers (``column`` (n,) within
    lines of ``width`` numbers), accept the NaN colours (appending their lines to
    ``nan_colors`` as (vertices, first line in the chunk)); MeshError at the first other one."""
    values, not_numbers = parse_floats(tokens.buf, tokens.starts[token], tokens.ends[token])
    colour = np.isnan(values) & (column >= 3) & (np.asarray(width) >= 6) & (which == V)
    colour[not_numbers] = False
    if not colour.all():
        floats_or_raise(tokens, path, token[~colour][:1], finite=True)
    lines = np.searchsorted(tokens.first, token, side="right") - 1
    nan_colors.append((len(np.unique(lines)), int(tokens.number[lines[0]])))


def reject_slashes(tokens: Tokens, path, lines) -> None:
    """MeshError at the first number of these v/vt/vn lines with a '/' right before or after it."""
    _, numbers = line_tokens(tokens, lines)
    buf = tokens.buf
    slashed = (buf[tokens.starts[numbers] - 1] == SLASH) | (buf[tokens.ends[numbers]] == SLASH)
    if slashed.any():
        token = numbers[np.argmax(slashed)]
        raise MeshError(path, tokens.line_of_token(token), f"unexpected '/' next to {tokens.text(token)!r}")


def check_colors(tokens: Tokens, path, lines, vertices) -> None:
    """MeshError at the first ``v x y z r g b`` line whose colour leaves [0, 1]."""
    if vertices.shape[1] < 6:
        return
    outside = ((vertices[:, 3:6] < 0) | (vertices[:, 3:6] > 1)).any(axis=1)
    if outside.any():
        raise MeshError(path, tokens.number[lines[np.argmax(outside)]], "vertex colour outside [0, 1]")
