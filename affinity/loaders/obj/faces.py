"""The faces phase of the OBJ reader: the corners of a chunk's ``f`` lines.

A face token's slot in its corner (``v``, ``vt`` or ``vn``) follows from the separator
before it: whitespace starts a corner, '/' moves to the next slot, '//' skips the ``vt``
slot. Two paths read the tokens, and both go through :func:`checked_corners` (the one
corner validator) and :func:`count_back` (the one fix-up of relative indices):

- the fast path, when every face line of the chunk is laid out like the first (the same
  separators between as many tokens: ``v/vt/vn`` quads, say): the indices parse as one
  ``(F, T)`` integer matrix, the first line's layout is validated for all, and a slot's
  columns are its corners;
- the general path, token by token, for anything else, and for any chunk the fast path
  finds wrong: it names the line of the first error, so both paths fail alike.

The validator's checks, in order over the chunk: an index that is no whole number or is 0,
a malformed corner, a face of fewer than 3 corners, a face mixing the corner forms. An index
counting back past the first element, or past the last, is found at assembly
(:meth:`affinity.loaders.obj.assembly.Assembly.mesh`), against the whole file.
"""

from __future__ import annotations

import numpy as np

from ...errors import MeshError
from ..numbers import parse_ints
from ..text import Tokens
from .scan import ELEMENT_OF_SLOT, SLASH, line_tokens, token_block

#: Bits of a face token's separator layout (see :func:`_face_layout`).
_AFTER_SLASH, _AFTER_DOUBLE, _BEFORE_SLASH, _BAD_GAP, _TRAILING, _TRAILING_DOUBLE = 1, 2, 4, 8, 16, 32


def _face_layout(buf, start, end, previous_end) -> np.ndarray:
    """(K,) uint8 per face token (bytes ``start:end``, previous token ending at
    ``previous_end``): which of '/', '//' precede it, whether '/' follows,
    whether the separator before it is anything but whitespace, '/' or '//',
    and whether the corner ends in empty slots: '/' or '//' then whitespace
    (``v/``, ``v//``, ``v/vt/``)."""
    after = buf[start - 1] == SLASH
    double = after & (buf[start - 2] == SLASH)
    bad_gap = after & (start - previous_end != 1 + double)
    layout = after.view(np.uint8) | (double.view(np.uint8) << 1) | (bad_gap.view(np.uint8) << 3)
    before = buf[end] == SLASH
    layout |= before.view(np.uint8) << 2
    if before.any():
        second = buf[end + 1]
        layout |= (before & (second <= 32)).view(np.uint8) << 4
        layout |= (before & (second == SLASH) & (buf[end + 2] <= 32)).view(np.uint8) << 5
    return layout


def _corner_slots(layout, line_start):
    """Slot (0 v, 1 vt, 2 vn) of every face token, and which tokens are malformed.

    layout : (K,) uint8 from :func:`_face_layout`; line_start : (K,) bool, the
    token is the first of its face line. Returns ``slot (K,) int8, malformed (K,) bool``.
    """
    after = (layout & _AFTER_SLASH) > 0
    double = (layout & _AFTER_DOUBLE) > 0
    slot = np.where(after, 1 + double, 0).astype(np.int8)
    single = after & ~double
    for _ in range(2):  # 'a/b/c': c follows b; two passes expose a fourth slot
        slot[1:] = np.where(single[1:], slot[:-1] + 1, slot[1:])
    joined_next = np.append(after[1:] & ~line_start[1:], False)
    empty_slots = ((layout & _TRAILING) > 0) + 2 * ((layout & _TRAILING_DOUBLE) > 0)
    malformed = ((layout & _BAD_GAP) > 0) | (after & line_start) | (slot + empty_slots > 2)
    malformed |= ((layout & _BEFORE_SLASH) > 0) & ~joined_next & (empty_slots == 0)
    return slot, malformed


def _slash_count(layout) -> int:
    """Number of '/' bytes the separators of these face tokens hold, empty trailing slots included."""
    counted = (_AFTER_SLASH, _AFTER_DOUBLE, _TRAILING, _TRAILING_DOUBLE, _TRAILING_DOUBLE)
    return sum(int(np.count_nonzero(layout & bit)) for bit in counted)


def face_corners(tokens: Tokens, path, kind, face_lines, fast: bool = True):
    """Corner structure of the chunk's ``f`` lines ``face_lines`` ((F,) int64 line indices;
    ``kind`` (L,) int8 the kind of every line).

    Returns ``sizes`` ((F,) int64, or an int when all faces have that size),
    ``corners``, ``relative`` and ``bounds`` as described in
    :class:`~affinity.loaders.obj.scan.Part`, and the number of '/' bytes between the face
    tokens. ``fast=False`` takes the general path whatever the layout.
    """
    if len(face_lines) == 0:
        return 0, [None] * 3, [None] * 3, [None] * 3, 0
    if fast:
        found = _block_faces(tokens, path, kind, face_lines)
        if found is not None:
            return found
    return _token_faces(tokens, path, kind, face_lines)


def _laid_out_alike(buf, start, end, previous_end) -> bool:
    """Whether every face line has the separators of the first, so that all
    share its :func:`_face_layout` bit for bit: the same gap before each token,
    ending in the same byte, starting with the same byte where the gap is
    longer than one; and the same byte after the line's last token.

    start, end, previous_end : (F, T) int64 offsets of the lines' tokens and
    of the ends of the tokens before them.
    """
    gap = start - previous_end
    if not (gap == gap[0]).all():
        return False
    last = buf[start - 1]
    if not (last == last[0]).all():
        return False
    wide = np.flatnonzero(gap[0] > 1)
    if len(wide):
        first = buf[previous_end[:, wide]]
        if not (first == first[0]).all():
            return False
    after = buf[end[:, -1]]
    return bool((after == after[0]).all())


def checked_corners(tokens: Tokens, path, index, values, bad, layout, line_tokens_start, face_lines):
    """The one corner validator: slots, corners and faces of face tokens, or MeshError.

    index : (K,) int64 the chunk's tokens checked (a face line's tokens follow each other);
    values, bad : (K,) int64 their values and the positions of those that are no integer
    (:func:`~affinity.loaders.numbers.parse_ints`); layout : (K,) uint8 (:func:`_face_layout`);
    line_tokens_start : (F + 1,) int64 the first of the tokens of every face line, then K;
    face_lines : (F,) int64 the lines.
    Returns ``slot`` (K,) int8, ``corner`` (K,) int64 (the corner of every token, from the
    first) and ``face_start`` (F + 1,) int64 (the first corner of every face).

    Raises at the first token that is no index (or 0), else the first malformed corner, else
    the first face of fewer than 3 corners, else the first face mixing the corner forms.
    """
    zero = np.flatnonzero(values == 0)
    if len(bad) or len(zero):
        token = index[np.concatenate([bad, zero]).min()]
        raise MeshError(path, tokens.line_of_token(token), f"bad index {tokens.text(token)!r} (indices start at 1)")
    line_start = np.zeros(len(layout), dtype=bool)
    opens = line_tokens_start[:-1]
    line_start[opens[opens < line_tokens_start[1:]]] = True
    slot, malformed = _corner_slots(layout, line_start)
    if malformed.any():
        token = index[np.argmax(malformed)]
        raise MeshError(path, tokens.line_of_token(token), f"malformed face corner near {tokens.text(token)!r}")
    corner_starts = np.concatenate(([0], np.cumsum(slot == 0)))
    face_start = corner_starts[line_tokens_start]
    sizes = np.diff(face_start)
    if (sizes < 3).any():
        line = face_lines[np.argmax(sizes < 3)]
        raise MeshError(path, tokens.number[line], f"face with {sizes[sizes < 3][0]} corners (at least 3 needed)")
    corner = corner_starts[1:] - 1
    form = np.zeros(corner_starts[-1], dtype=np.int8)  # 0: v, 1: v/vt, 2: v//vn, 3: v/vt/vn
    for which in (1, 2):  # a corner has each slot at most once: no repeated indices
        form[corner[slot == which]] += which
    mixed = np.minimum.reduceat(form, face_start[:-1]) != np.maximum.reduceat(form, face_start[:-1])
    if mixed.any():
        line = face_lines[np.argmax(mixed)]
        raise MeshError(path, tokens.number[line], "face corners mix the forms v, v/vt, v//vn, v/vt/vn")
    return slot, corner, face_start


def count_back(index: np.ndarray, back: np.ndarray, defined) -> tuple[int, int]:
    """The one fix-up of relative (negative) OBJ indices, in place: ``index[back] += defined``.

    index : (C,) int64. A relative index ``-n`` is stored as ``-n - 1`` (as every index, minus
    one) and names element ``count - n``, ``count`` the elements of its kind defined above its
    line: the chunk adds ``1 +`` the count within the chunk ((len(back),) int64), the assembly
    the count before the chunk (an int). Returns (min, max) of ``index[back]``: a negative one
    counts back past the elements known so far.
    """
    index[back] += defined
    return int(index[back].min()), int(index[back].max())


def _slot_corners(kind, face_lines, face_start, picked: np.ndarray, element: int):
    """``corners``, ``relative`` and ``bounds`` of one slot (see :class:`~.scan.Part`) from its
    (C,) int64 indices ``picked`` (index - 1 as read, -1 where a corner lacks the slot),
    relative indices fixed up by the elements of kind ``element`` above their line."""
    low, high = int(picked.min()), int(picked.max())
    if low >= -1:
        return picked, None, (low, high)
    back = np.flatnonzero(picked < -1)
    line = face_lines[np.searchsorted(face_start, back, side="right") - 1]
    count_back(picked, back, 1 + np.cumsum(kind == element)[line])
    absolute = np.ones(len(picked), dtype=bool)
    absolute[back] = False
    rest = picked[absolute]
    return picked, back, (int(rest.min()), int(rest.max())) if len(rest) else (0, -1)


def _block_faces(tokens: Tokens, path, kind, face_lines):
    """The fast path: faces whose lines are all laid out like the first, their indices one
    (F, T) matrix; None when they are not, or when something is wrong with them (the general
    path then says what, and where)."""
    counts = tokens.counts[face_lines]
    width = int(counts[0]) - 1
    if width == 0 or counts.min() != counts.max():
        return None
    start, end, previous_end = token_block(tokens, face_lines, width, previous=True)
    if not _laid_out_alike(tokens.buf, start, end, previous_end):
        return None
    layout = _face_layout(tokens.buf, start[0], end[0], previous_end[0])
    # Empty trailing slots depend on bytes the cheap comparison does not look at
    # ('/  ' and '// ' gaps look alike to it): compare every line.
    if (layout & (_TRAILING | _TRAILING_DOUBLE)).any() and \
            not (_face_layout(tokens.buf, start, end, previous_end) == layout).all():
        return None
    values, bad = parse_ints(tokens.buf, start, end)
    if len(bad):
        return None
    first_line = tokens.first[face_lines[0]] + 1 + np.arange(width)
    try:  # the first line's layout is every line's
        slot, _, first_face = checked_corners(tokens, path, first_line, values[0], bad, layout,
                                              np.array([0, width]), face_lines[:1])
    except MeshError:
        return None
    size = int(first_face[1])
    face_start = np.arange(0, size * len(face_lines) + 1, size)
    corners, relative, bounds = [None] * 3, [None] * 3, [None] * 3
    for which, element in enumerate(ELEMENT_OF_SLOT):
        columns = np.flatnonzero(slot == which)
        if len(columns) == 0:
            continue
        step = int(columns[1] - columns[0]) if len(columns) > 1 else 1
        if (columns == columns[0] + step * np.arange(len(columns))).all():  # a strided view
            picked = values[:, columns[0] :: step][:, : len(columns)] - 1
        else:
            picked = values[:, columns] - 1
        corners[which], relative[which], bounds[which] = _slot_corners(kind, face_lines, face_start,
                                                                       picked.reshape(-1), element)
        if bounds[which][0] == -1:  # an index 0 (no corner lacks the slot here), not seen in the first line
            return None
    return size, corners, relative, bounds, _slash_count(layout) * len(face_lines)


def _token_faces(tokens: Tokens, path, kind, face_lines):
    """The general path: face lines of any widths and layouts, token by token."""
    width, index = line_tokens(tokens, face_lines)
    start, end = tokens.starts[index], tokens.ends[index]
    layout = _face_layout(tokens.buf, start, end, tokens.ends[index - 1])
    values, bad = parse_ints(tokens.buf, start, end)
    line_tokens_start = np.concatenate(([0], np.cumsum(width)))
    slot, corner, face_start = checked_corners(tokens, path, index, values, bad, layout, line_tokens_start,
                                               face_lines)
    corners, relative, bounds = [None] * 3, [None] * 3, [None] * 3
    for which, element in enumerate(ELEMENT_OF_SLOT):
        own = slot == which
        if not own.any():
            continue
        picked = np.full(int(face_start[-1]), -1, dtype=np.int64)
        picked[corner[own]] = values[own] - 1
        corners[which], relative[which], bounds[which] = _slot_corners(kind, face_lines, face_start, picked, element)
    return np.diff(face_start), corners, relative, bounds, _slash_count(layout)
