"""The OBJ reader's fast scan: a chunk of lines laid out alike, read as byte columns.

A chunk whose lines fall into a few groups laid out alike (every line of a group the same
bytes as the group's first line but for its digits: same keyword, signs, points and
separators) is read as byte columns (:mod:`affinity.loaders.columns`): no tokens, each number
read at offsets fixed for its group. That is the common exported file (``%.6f``
coordinates, ``v/vt/vn`` faces). A chunk holding any line this path does not take
(statements, trailing comments, exponents, colours, index 0, ...) is left to the token
reader, which also names the line of every error.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ..columns import Group, alike_groups
from ..numbers import PAD, eight_digits
from .scan import VN, VT, WIDTHS, F, Part, V

#: Layouts a chunk may hold and still be read as groups of lines laid out alike.
_ALIKE_LIMIT = 32
#: The longest line the column reader takes: a layout is read from a group's first line byte by
#: byte, in Python, so a face of many corners (a line of megabytes) goes to the token reader.
_ALIKE_LINE_BYTES = 4096
_TEXT_LINE = re.compile(rb"[\t -~]*\r?\n")
_OBJ_TOKEN = re.compile(rb"[^ \t\r\n/]+")
_DECIMAL = re.compile(rb"([-+]?)(\d+)(?:\.(\d+))?")
_KINDS = {b"v": V, b"vt": VT, b"vn": VN, b"f": F}
#: Numbers per line the column reader takes (colours and ``w`` go to the token reader).
_ALIKE_WIDTHS = {V: (3,), VT: (1, 2, 3), VN: (3,)}


@dataclass
class _Layout:
    """How to read the lines of one :class:`~affinity.loaders.columns.Group`.

    ``spans`` are runs of at most 8 bytes holding digits (and, at ``dots``, a
    decimal point). For ``v``/``vt``/``vn`` lines number ``t`` is run ``last[t]``
    plus ``weight`` times run ``s`` for each ``(s, t, weight)`` of ``extra`` (the
    runs before it, when it is longer than 8 bytes), over ``divisor[t]`` (which
    carries the sign); for faces every run is one index, of slot ``slots[t]``.
    """

    kind: int
    spans: list
    dots: list | None = None
    last: list | None = None
    extra: list | None = None
    divisor: np.ndarray | None = None  # (T,) float64
    slots: tuple = ()
    size: int = 0  # corners of a face


def _line_layout(first: bytes) -> _Layout | None:
    """The :class:`_Layout` of lines laid out like ``first`` (kind 0: a blank or comment line),
    None when the token reader must read them (statements, trailing comments, exponents,
    colours, ...)."""
    if not _TEXT_LINE.fullmatch(first):
        return None
    tokens = list(_OBJ_TOKEN.finditer(first))
    if not tokens or tokens[0].group().startswith(b"#"):  # blank, or a comment line
        return _Layout(0, [])
    kind = _KINDS.get(tokens[0].group())
    if kind == F:
        return _face_layout_of(first, tokens[1:])
    if kind is None or b"/" in first or len(tokens) - 1 not in _ALIKE_WIDTHS[kind]:
        return None
    layout = _Layout(kind, [], dots=[], last=[], extra=[])
    divisor = []
    for token in tokens[1:]:
        number = _DECIMAL.fullmatch(token.group())
        if number is None or len(number.group(2) + (number.group(3) or b"")) > 15:  # > 2**53: not exact
            return None
        start, end = token.start() + len(number.group(1)), token.end()
        dot = token.start() + number.start(3) - 1 if number.group(3) else -1
        after = 0  # digits after the run
        for run_end in range(end, start, -8):
            run_start = max(start, run_end - 8)
            if after:
                layout.extra.append((len(layout.spans), len(divisor), 10.0**after))
            else:
                layout.last.append(len(layout.spans))
            layout.spans.append((run_start, run_end))
            layout.dots.append(dot if run_start <= dot < run_end else -1)
            after += run_end - run_start - (run_start <= dot < run_end)
        sign = -1.0 if number.group(1) == b"-" else 1.0
        divisor.append(sign * 10.0 ** len(number.group(3) or b""))
    layout.divisor = np.array(divisor)
    return layout


def _face_layout_of(first: bytes, tokens) -> _Layout | None:
    """The :class:`_Layout` of ``f`` lines like ``first`` (``tokens``: its indices), or None."""
    corners = first.split()[1:]
    forms = set()
    for corner in corners:
        parts = corner.split(b"/")
        if len(parts) > 3 or not all(parts[:1] + parts[2:]) or (len(parts) == 2 and not parts[1]):
            return None
        forms.add(tuple(k for k, part in enumerate(parts) if part))
    if len(forms) != 1 or len(corners) < 3:
        return None
    slots = forms.pop()
    if any(len(token.group()) > 8 or not token.group().isdigit() for token in tokens):
        return None
    return _Layout(F, [token.span() for token in tokens], slots=slots * len(corners), size=len(corners))


def alike_part(chunk) -> Part | None:
    """The chunk read as groups of lines laid out alike (:mod:`affinity.loaders.columns`),
    or None when some line needs the token reader (which then finds any error)."""
    if len(chunk.joined):
        return None
    buf = chunk.buf
    end = np.flatnonzero(buf == ord("\n"))
    begin = np.empty_like(end)
    begin[:1] = PAD
    np.add(end[:-1], 1, out=begin[1:])
    if (end - begin).max(initial=0) > _ALIKE_LINE_BYTES:
        return None
    groups = alike_groups(buf, begin, end, _ALIKE_LIMIT)
    if groups is None:
        return None
    layouts = [_line_layout(group.first) for group in groups]
    if None in layouts:
        return None
    kind = np.zeros(len(end), np.int8)
    for group, layout in zip(groups, layouts):
        kind[group.rows] = layout.kind
    elements = {}
    for which in WIDTHS:
        own = [(g, layout) for g, layout in zip(groups, layouts) if layout.kind == which]
        if len({len(layout.divisor) for _, layout in own}) > 1:
            return None
        blocks = [(g.rows, _alike_numbers(g, layout)) for g, layout in own]
        elements[which] = _in_file_order(kind, which, blocks, (WIDTHS[which][0], 0), np.float64)
    faces = [(g, layout) for g, layout in zip(groups, layouts) if layout.kind == F]
    if len({layout.slots for _, layout in faces}) > 1:
        return None
    corners, bounds = [None] * 3, [None] * 3
    if faces:
        found = _alike_corners(kind, faces)
        if found is None:  # index 0: the token reader says where
            return None
        corners, bounds = found
    return Part(
        elements=elements,
        face_sizes=faces[0][1].size if faces else 0,
        face_line=np.flatnonzero(kind == F) + 1,
        corners=corners,
        relative=[None] * 3,
        bounds=bounds,
        lines=len(end),
        bytes=len(buf) - 2 * PAD,
    )


def _alike_corners(kind, faces) -> tuple[list, list] | None:
    """``corners`` and ``bounds`` (see :class:`Part`) of the chunk's ``f`` lines, ``faces``
    (group, layout) pairs of one corner form; None when some index is 0.

    A slot whose digits are those of the vertex slot in every corner (``f 7/7/7 ...``:
    attributes stored per vertex, as many exporters write them) is not parsed again:
    it gets the vertex slot's array itself.
    """
    slots = np.array(faces[0][1].slots)
    windows = [(g.rows, g.windows(layout.spans)) for g, layout in faces]  # (T, n) digits of each index
    vertex = np.flatnonzero(slots == 0)
    twins = [which for which in (1, 2) if (slots == which).any()
             and all(np.array_equal(digits[own], digits[first])  # row by row: views, no copies
                     for _, digits in windows for own, first in zip(np.flatnonzero(slots == which), vertex))]
    parsed = ~np.isin(slots, twins)
    blocks = [(rows, eight_digits(digits if parsed.all() else digits[parsed]).view(np.int64))
              for rows, digits in windows]
    indices = _in_file_order(kind, F, blocks, (int(parsed.sum()), 0), np.int64)  # (T, n)
    if not indices.all():
        return None
    corners, bounds = [None] * 3, [None] * 3
    for which in set(slots[parsed].tolist()):
        own = slots[parsed] == which
        picked = np.empty((indices.shape[1], int(own.sum())), np.int64)  # corner-major: (faces, corners)
        np.subtract((indices if own.all() else indices[own]).T, 1, out=picked)
        picked = picked.reshape(-1)
        corners[which], bounds[which] = picked, (int(picked.min()), int(picked.max()))
    for which in twins:
        corners[which], bounds[which] = corners[0], bounds[0]
    return corners, bounds


def _alike_numbers(group: Group, layout: _Layout) -> np.ndarray:
    """(T, n) float64 numbers of a group of ``v``/``vt``/``vn`` lines, by component."""
    runs = group.numbers(layout.spans, layout.dots).view(np.int64).astype(np.float64)
    values = runs if len(layout.last) == len(layout.spans) else runs[layout.last]
    for run, column, weight in layout.extra:  # exact: integers below 2**53
        values[column] += runs[run] * weight
    values /= layout.divisor[:, None]
    return values


def _in_file_order(kind, which, blocks, empty_shape, dtype) -> np.ndarray:
    """(T, n) values of the ``which`` lines, by component, from ``blocks`` of (line indices, (T, n)
    values), in file order."""
    if len(blocks) == 1:
        return blocks[0][1]
    if not blocks:
        return np.zeros(empty_shape, dtype)
    rank = np.cumsum(kind == which) - 1
    out = np.empty((blocks[0][1].shape[0], int(rank[-1]) + 1), dtype)
    for rows, values in blocks:
        at = rank[rows]
        for column, value in zip(out, values):  # 1-D scatters: several times faster than one 2-D
            column[at] = value
    return out

