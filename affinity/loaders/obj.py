"""Wavefront OBJ reader, vectorized over lines and corners.

A chunk whose lines fall into a few groups laid out alike (every line of a
group the same bytes as the group's first line but for its digits: same
keyword, signs, points and separators) is read as byte columns
(:mod:`affinity.loaders.columns`): no tokens, each number read at offsets fixed
for its group. That is the common exported file (``%.6f`` coordinates,
``v/vt/vn`` faces). Any other chunk, and any chunk holding a line the column
path does not take (statements, trailing comments, exponents, colours, index 0, ...),
goes to the token reader below, which also names the line of every error.

Otherwise each chunk of lines is tokenized once at whitespace and '/'. Lines are
classified by their keyword token (``v``, ``vt``, ``vn``, ``f``); the numbers of
all lines of one kind are parsed in one call and reshaped by their per-line
counts. A face token's role in its corner (``v``, ``vt`` or ``vn`` slot) follows
from the separator before it: whitespace starts a corner, '/' moves to the next
slot, '//' skips the ``vt`` slot. Statements without bulk (``g``, ``o``,
``usemtl``, ``mtllib``, ``s``, ``l``, ...) are rare and handled one by one.

The common file is regular: within a chunk, the lines of one kind follow each
other and carry the same number of tokens, and every face line is laid out
like the first (``v/vt/vn`` quads, say). Then the numbers of a kind are one
``(lines, tokens)`` block read straight out of the token arrays, and faces are
parsed as one integer matrix whose columns are the corners' slots; anything
else takes the general path, token by token.

Chunks are parsed on worker threads (NumPy releases the GIL inside its loops)
while the main thread reads the file and appends each finished chunk, in file
order, to the growing arrays of the mesh, so no chunk's arrays outlive it.

Indices may be negative (relative to the elements defined so far) and may refer
to elements defined later in the file; every index is range-checked against the
whole file.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import MeshError
from ..mesh import Mesh
from .columns import Group, alike_groups
from .faces import check_indices, color_note, ragged_positions
from .numbers import PAD, eight_digits, parse_floats, parse_ints
from .regular import read_regular
from .resources import obj_resources, uncommented
from .text import BufferReader, NotText, Tokens, floats_or_raise, read_chunks, tokenize
from .texturemaps import obj_material_maps

_V, _VT, _VN, _F = 1, 2, 3, 4
#: Numbers a line of each kind may carry: ``v x y z [w]``, ``v x y z r g b [a]``,
#: ``vt u [v [w]]``, ``vn x y z``.
_WIDTHS = {_V: (3, 4, 6, 7), _VT: (1, 2, 3), _VN: (3,)}
_MAX_WIDTH = 8
#: ``_ALLOWED[kind][min(n, 8)]``: a line of that kind may carry ``n`` numbers.
_ALLOWED = {kind: np.isin(np.arange(_MAX_WIDTH + 1), widths) for kind, widths in _WIDTHS.items()}
_ELEMENT_OF_SLOT = (_V, _VT, _VN)
_SLOT_NAMES = ("vertex", "texture coordinate", "normal")
_SLASH = ord("/")
_KEYWORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


@dataclass
class _Part:
    """What one chunk contributes; indices are still relative to the chunk.

    ``corners[k]`` is (C,) int64 0-based index for slot ``k`` (vertex, texcoord,
    normal), -1 where a corner lacks it, or None when no corner of the chunk
    has the slot; ``relative[k]`` lists the corners whose index counted back
    from the chunk's own elements and still needs the count of elements before
    the chunk added. ``bounds[k]`` is (min, max) of ``corners[k]`` without them.
    ``face_sizes`` is an int when every face of the chunk has that many corners.
    Line numbers count from the chunk's first line (see :meth:`_Assembly.result`).
    """

    elements: dict  # kind -> (width, n) float64, by component
    face_sizes: np.ndarray | int
    face_line: np.ndarray
    corners: list
    relative: list
    bounds: list
    lines: int  # lines of the chunk
    bytes: int  # bytes of the chunk's lines
    events: list = field(default_factory=list)  # (face in chunk, keyword, name)
    nan_colors: list = field(default_factory=list)  # (vertices, first line) with a NaN colour
    #: The chunk may hold an ``mtllib`` statement. The column reader's chunks cannot (every line of
    #: theirs starts with v, vt, vn, f or '#'); the token reader's say so when the word is in their bytes.
    mtllib: bool = False


#: Chunks parsed in parallel (NumPy releases the GIL inside its loops).
_WORKERS = 2

#: Every keyword of the OBJ format (Advanced Visualizer manual, Appendix B1), and ``fo``, an
#: old spelling of ``f``: a chunk holding none of them is not OBJ (prose, a CSV, a log).
_OBJ_KEYWORDS = frozenset(
    "v vt vn vp f fo l p cstype deg bmat step curv curv2 surf parm trim hole scrv sp end con g s mg o "
    "bevel c_interp d_interp lod usemtl mtllib shadow_obj trace_obj ctech stech maplib usemap".split()
)
#: Statements that may run longer than a chunk: faces, lines and points of many corners,
#: free-form lists, group names, comments.
_LONG_LINE = re.compile(rb"[ \t]*(?:#|(?:fo?|l|p|g|curv2?|surf|parm|trim|hole|scrv|sp|con)[ \t])")


def load_obj(path, chunk_bytes: int | None = None, source: bytes | None = None, fast: bool = True) -> Mesh:
    """Read a Wavefront OBJ file (and the texture maps of its ``mtllib`` files, ``Mesh.resources``).

    ``chunk_bytes`` (default :data:`~affinity.loaders.text.CHUNK_BYTES`) is how
    much is parsed at a time; the mesh does not depend on it. ``source`` is the
    file's bytes when the caller has read them already (the check hashes them
    for its cache and scans them for inline ignores: one read of the file).
    ``fast=False`` reads every chunk on the general path, token by token: the mesh, and the
    error of a bad file, are the same (a test compares the two paths).
    """
    from concurrent.futures import ThreadPoolExecutor  # here, not at import: off a cached check's path

    if source is None:
        source = read_regular(path)
    pending = []
    with ThreadPoolExecutor(_WORKERS) as pool:
        assembly = _Assembly(len(source))
        chunks = read_chunks(BufferReader(source), path, continuations=True, size=chunk_bytes, count_lines=False,
                             long_line=_LONG_LINE)
        try:
            for chunk in chunks:
                pending.append(pool.submit(_parse_chunk, chunk, path, fast))
                if len(pending) > 2 * _WORKERS:  # bound the chunks held in memory
                    assembly.add(assembly.result(pending.pop(0)))
        except NotText as error:  # the lines before the bad bytes speak first; then its line is known
            for future in pending:
                assembly.add(assembly.result(future))
            raise MeshError(path, assembly.n_lines + 1, error.reason) from None
        for future in pending:
            assembly.add(assembly.result(future))
    # Only a file with an mtllib statement has resources: the others' bytes are not searched again.
    return assembly.mesh(path, obj_resources(os.fspath(path), source) if assembly.mtllib else [])


def _parse_chunk(chunk, path, fast: bool) -> _Part:
    part = _alike_part(chunk) if fast else None
    if part is not None:
        return part
    tokens = tokenize(chunk, path, slash=True)
    counts = tokens.counts
    kind = _line_kinds(tokens, counts)
    element_lines = {k: np.flatnonzero(kind == k) for k in _WIDTHS}
    nan_colors = []
    elements = {k: _elements(tokens, path, lines, k, nan_colors, fast) for k, lines in element_lines.items()}
    _check_colors(tokens, path, element_lines[_V], elements[_V])
    elements = {k: rows.T for k, rows in elements.items()}  # by component, as the column reader gives them
    face_lines = np.flatnonzero(kind == _F)
    sizes, corners, relative, bounds, face_slashes = _faces(tokens, path, kind, face_lines, fast)
    if tokens.slashes != face_slashes:
        # Some '/' is not where a face layout puts one; when every one is, none
        # can touch a number of a v/vt/vn line and the lines need no look.
        for lines in element_lines.values():
            _reject_slashes(tokens, path, lines)
    part = _Part(
        elements=elements,
        face_sizes=sizes,
        face_line=tokens.number[face_lines],
        corners=corners,
        relative=relative,
        bounds=bounds,
        lines=len(tokens.end) + len(chunk.joined),
        bytes=len(chunk.buf) - 2 * PAD,
        nan_colors=nan_colors,
        mtllib=chunk.find(b"mtllib") >= 0,
    )
    statements = np.flatnonzero((counts > 0) & (kind == 0))
    if len(statements) and not kind.any():
        _require_statement(tokens, path, statements, chunk.offset)
    if len(statements):
        faces_before = np.cumsum(kind == _F)
        for line in statements:
            _statement(tokens, path, line, int(faces_before[line]), part)
    return part


#: Layouts a chunk may hold and still be read as groups of lines laid out alike.
_ALIKE_LIMIT = 32
#: The longest line the column reader takes: a layout is read from a group's first line byte by
#: byte, in Python, so a face of many corners (a line of megabytes) goes to the token reader.
_ALIKE_LINE_BYTES = 4096
_TEXT_LINE = re.compile(rb"[\t -~]*\r?\n")
_OBJ_TOKEN = re.compile(rb"[^ \t\r\n/]+")
_DECIMAL = re.compile(rb"([-+]?)(\d+)(?:\.(\d+))?")
_KINDS = {b"v": _V, b"vt": _VT, b"vn": _VN, b"f": _F}
#: Numbers per line the column reader takes (colours and ``w`` go to the token reader).
_ALIKE_WIDTHS = {_V: (3,), _VT: (1, 2, 3), _VN: (3,)}
#: Corner forms as the slots present: v, v/vt, v//vn, v/vt/vn.
_FORMS = {1: (0,), 2: (0, 1), 3: (0, 1, 2)}


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
    if kind == _F:
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
    return _Layout(_F, [token.span() for token in tokens], slots=slots * len(corners), size=len(corners))


def _alike_part(chunk) -> _Part | None:
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
    for which in _WIDTHS:
        own = [(g, layout) for g, layout in zip(groups, layouts) if layout.kind == which]
        if len({len(layout.divisor) for _, layout in own}) > 1:
            return None
        blocks = [(g.rows, _alike_numbers(g, layout)) for g, layout in own]
        elements[which] = _in_file_order(kind, which, blocks, (_WIDTHS[which][0], 0), np.float64)
    faces = [(g, layout) for g, layout in zip(groups, layouts) if layout.kind == _F]
    if len({layout.slots for _, layout in faces}) > 1:
        return None
    corners, bounds = [None] * 3, [None] * 3
    if faces:
        found = _alike_corners(kind, faces)
        if found is None:  # index 0: the token reader says where
            return None
        corners, bounds = found
    return _Part(
        elements=elements,
        face_sizes=faces[0][1].size if faces else 0,
        face_line=np.flatnonzero(kind == _F) + 1,
        corners=corners,
        relative=[None] * 3,
        bounds=bounds,
        lines=len(end),
        bytes=len(buf) - 2 * PAD,
    )


def _alike_corners(kind, faces) -> tuple[list, list] | None:
    """``corners`` and ``bounds`` (see :class:`_Part`) of the chunk's ``f`` lines, ``faces``
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
    indices = _in_file_order(kind, _F, blocks, (int(parsed.sum()), 0), np.int64)  # (T, n)
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


def _line_kinds(tokens: Tokens, counts) -> np.ndarray:
    """(L,) int8 kind of every line from its keyword token; 0 for anything else."""
    buf = tokens.buf
    kind = np.zeros(len(counts), dtype=np.int8)
    if len(tokens.starts) == 0:
        return kind
    keyword = np.minimum(tokens.first[:-1], len(tokens.starts) - 1)
    start = tokens.starts[keyword]
    length = tokens.ends[keyword] - start
    length[counts == 0] = 0
    first, second = buf[start], buf[start + 1]
    one, two, v = length == 1, length == 2, first == ord("v")
    kind[one & v] = _V
    kind[one & (first == ord("f"))] = _F
    if two.any():
        two &= v
        kind[two & (second == ord("t"))] = _VT
        kind[two & (second == ord("n"))] = _VN
    return kind


def _line_tokens(tokens: Tokens, lines):
    """Tokens after the keyword of ``lines``: per-line count (n,) and indices (sum,) int64."""
    width = tokens.counts[lines] - 1
    return width, ragged_positions(tokens.first[lines] + 1, width)


def _token_block(tokens: Tokens, lines, width: int, previous: bool = False):
    """Byte offsets of the ``width`` tokens after the keyword of every line of
    ``lines``, all of which have that many: ``starts, ends`` (n, width) int64
    (and the ends of the tokens before them with ``previous``). A run of
    consecutive lines owns a contiguous range of tokens: then they are views."""
    n = len(lines)
    if n and lines[-1] - lines[0] + 1 == n:
        first = tokens.first[lines[0]]
        rows = slice(first, first + n * (width + 1))
        starts = tokens.starts[rows].reshape(n, width + 1)
        ends = tokens.ends[rows].reshape(n, width + 1)
        block = starts[:, 1:], ends[:, 1:]
        return block + (ends[:, :-1],) if previous else block
    index = tokens.first[lines, None] + np.arange(1, width + 1)
    block = tokens.starts[index], tokens.ends[index]
    return block + (tokens.ends[index - 1],) if previous else block


def _elements(tokens: Tokens, path, lines, which, nan_colors: list, fast: bool) -> np.ndarray:
    """(n, width) float64 numbers of the ``which`` lines, NaN where a line has fewer.

    NaN colours (``v x y z r g b`` lines) are kept and counted in ``nan_colors``
    (see :func:`_nan_colors_or_raise`); every other number must be finite.
    """
    if len(lines) == 0:
        return np.zeros((0, _WIDTHS[which][0]))
    counts = tokens.counts[lines]
    if fast and counts.min() == counts.max() and _ALLOWED[which][min(counts[0] - 1, _MAX_WIDTH)]:
        width = int(counts[0]) - 1  # one width: a (lines, numbers) block
        starts, ends = _token_block(tokens, lines, width)
        rows, bad = parse_floats(tokens.buf, starts, ends, finite=True)
        if len(bad):
            line, column = bad // width, bad % width
            token = tokens.first[lines[line]] + 1 + column
            _nan_colors_or_raise(tokens, path, which, token, column, width, nan_colors)
    else:
        width, numbers = _line_tokens(tokens, lines)
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
        rows = np.full((len(width), max(int(width.max()), _WIDTHS[which][0])), np.nan)
        rows[np.repeat(np.arange(len(width)), width), ragged_positions(np.zeros(len(width), np.int64), width)] = values
    if which != _V or rows.shape[1] == 3:
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
    colour = np.isnan(values) & (column >= 3) & (np.asarray(width) >= 6) & (which == _V)
    colour[not_numbers] = False
    if not colour.all():
        floats_or_raise(tokens, path, token[~colour][:1], finite=True)
    lines = np.searchsorted(tokens.first, token, side="right") - 1
    nan_colors.append((len(np.unique(lines)), int(tokens.number[lines[0]])))


def _reject_slashes(tokens: Tokens, path, lines) -> None:
    """MeshError at the first number of these v/vt/vn lines with a '/' right before or after it."""
    _, numbers = _line_tokens(tokens, lines)
    buf = tokens.buf
    slashed = (buf[tokens.starts[numbers] - 1] == _SLASH) | (buf[tokens.ends[numbers]] == _SLASH)
    if slashed.any():
        token = numbers[np.argmax(slashed)]
        raise MeshError(path, tokens.line_of_token(token), f"unexpected '/' next to {tokens.text(token)!r}")


def _check_colors(tokens: Tokens, path, lines, vertices) -> None:
    """MeshError at the first ``v x y z r g b`` line whose colour leaves [0, 1]."""
    if vertices.shape[1] < 6:
        return
    outside = ((vertices[:, 3:6] < 0) | (vertices[:, 3:6] > 1)).any(axis=1)
    if outside.any():
        raise MeshError(path, tokens.number[lines[np.argmax(outside)]], "vertex colour outside [0, 1]")


#: Bits of a face token's separator layout (see :func:`_face_layout`).
_AFTER_SLASH, _AFTER_DOUBLE, _BEFORE_SLASH, _BAD_GAP, _TRAILING, _TRAILING_DOUBLE = 1, 2, 4, 8, 16, 32


def _face_layout(buf, start, end, previous_end) -> np.ndarray:
    """(K,) uint8 per face token (bytes ``start:end``, previous token ending at
    ``previous_end``): which of '/', '//' precede it, whether '/' follows,
    whether the separator before it is anything but whitespace, '/' or '//',
    and whether the corner ends in empty slots: '/' or '//' then whitespace
    (``v/``, ``v//``, ``v/vt/``)."""
    after = buf[start - 1] == _SLASH
    double = after & (buf[start - 2] == _SLASH)
    bad_gap = after & (start - previous_end != 1 + double)
    layout = after.view(np.uint8) | (double.view(np.uint8) << 1) | (bad_gap.view(np.uint8) << 3)
    before = buf[end] == _SLASH
    layout |= before.view(np.uint8) << 2
    if before.any():
        second = buf[end + 1]
        layout |= (before & (second <= 32)).view(np.uint8) << 4
        layout |= (before & (second == _SLASH) & (buf[end + 2] <= 32)).view(np.uint8) << 5
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


def _faces(tokens: Tokens, path, kind, face_lines, fast: bool):
    """Corner structure of the chunk's ``f`` lines.

    Returns ``sizes`` ((F,) int64, or an int when all faces have that size),
    ``corners``, ``relative`` and ``bounds`` as described in :class:`_Part`, and
    the number of '/' bytes between the face tokens.
    """
    if len(face_lines) == 0:
        return 0, [None] * 3, [None] * 3, [None] * 3, 0
    counts = tokens.counts[face_lines]
    width = int(counts[0]) - 1
    if fast and width > 0 and counts.min() == counts.max():
        start, end, previous_end = _token_block(tokens, face_lines, width, previous=True)
        if _laid_out_alike(tokens.buf, start, end, previous_end):
            layout = _face_layout(tokens.buf, start[0], end[0], previous_end[0])
            # Empty trailing slots depend on bytes the cheap comparison does not
            # look at ('/  ' and '// ' gaps look alike to it): compare every line.
            if not (layout & (_TRAILING | _TRAILING_DOUBLE)).any() or \
                    (_face_layout(tokens.buf, start, end, previous_end) == layout).all():
                return _uniform_faces(tokens, path, kind, face_lines, start, end, layout)
    return _mixed_faces(tokens, path, kind, face_lines)


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


def _raise_bad_index(tokens: Tokens, path, token) -> None:
    raise MeshError(path, tokens.line_of_token(token), f"bad index {tokens.text(token)!r} (indices start at 1)")


def _uniform_faces(tokens: Tokens, path, kind, face_lines, start, end, layout):
    """Faces whose lines are all laid out like the first: ``start``/``end`` (F, T)
    offsets of their tokens, ``layout`` (T,) of the first line. The index block
    parses as one (F, T) matrix; a slot's columns are its corners."""
    n_faces, width = start.shape

    def token_at(flat):
        return tokens.first[face_lines[flat // width]] + 1 + flat % width

    values, bad = parse_ints(tokens.buf, start, end)
    if len(bad):
        _raise_bad_index(tokens, path, token_at(int(bad[0])))
    slot, malformed = _corner_slots(layout, np.arange(len(layout)) == 0)
    if malformed.any():
        token = token_at(int(np.argmax(malformed)))
        raise MeshError(path, tokens.line_of_token(token), f"malformed face corner near {tokens.text(token)!r}")
    corner = np.cumsum(slot == 0) - 1
    size = int(corner[-1]) + 1
    if size < 3:
        raise MeshError(path, tokens.number[face_lines[0]], f"face with {size} corners (at least 3 needed)")
    forms = np.zeros(size, dtype=np.int8)  # 0: v, 1: v/vt, 2: v//vn, 3: v/vt/vn
    for which in (1, 2):
        forms[corner[slot == which]] += which
    if forms.min() != forms.max():
        raise MeshError(path, tokens.number[face_lines[0]], "face corners mix the forms v, v/vt, v//vn, v/vt/vn")

    corners, relative, bounds = [None] * 3, [None] * 3, [None] * 3
    for which in range(3):
        columns = np.flatnonzero(slot == which)
        if len(columns) == 0:
            continue
        step = int(columns[1] - columns[0]) if len(columns) > 1 else 1
        if (columns == columns[0] + step * np.arange(len(columns))).all():  # a strided view
            picked = values[:, columns[0] :: step][:, : len(columns)] - 1
        else:
            picked = values[:, columns] - 1
        picked = picked.reshape(-1)
        low, high = int(picked.min()), int(picked.max())
        if low < 0:  # zero (an error) or counted back from the line (relative)
            zero = np.flatnonzero(values.reshape(-1) == 0)
            if len(zero):
                _raise_bad_index(tokens, path, token_at(int(zero[0])))
            back = np.flatnonzero(picked < 0)
            line = face_lines[back // size]
            picked[back] += 1 + np.cumsum(kind == _ELEMENT_OF_SLOT[which])[line]
            rest = np.ones(len(picked), dtype=bool)
            rest[back] = False
            relative[which] = back
            low, high = (int(picked[rest].min()), int(picked[rest].max())) if rest.any() else (0, -1)
        corners[which], bounds[which] = picked, (low, high)
    return size, corners, relative, bounds, _slash_count(layout) * n_faces


def _mixed_faces(tokens: Tokens, path, kind, face_lines):
    """Face lines of differing widths or layouts, token by token."""
    buf = tokens.buf
    width, index = _line_tokens(tokens, face_lines)
    start, end = tokens.starts[index], tokens.ends[index]
    layout = _face_layout(buf, start, end, tokens.ends[index - 1])
    values, bad = parse_ints(buf, start, end)
    if len(bad) or not values.all():
        token = index[np.concatenate([bad, np.flatnonzero(values == 0)]).min()]
        _raise_bad_index(tokens, path, token)
    line_start = np.zeros(len(layout), dtype=bool)
    token_offsets = np.concatenate(([0], np.cumsum(width)))
    line_start[token_offsets[:-1][width > 0]] = True
    slot, malformed = _corner_slots(layout, line_start)
    if malformed.any():
        token = index[np.argmax(malformed)]
        raise MeshError(path, tokens.line_of_token(token), f"malformed face corner near {tokens.text(token)!r}")
    corner_starts = np.concatenate(([0], np.cumsum(slot == 0)))
    face_start = corner_starts[token_offsets]
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

    corners, relative, bounds = [None] * 3, [None] * 3, [None] * 3
    for which, element in enumerate(_ELEMENT_OF_SLOT):
        own = slot == which
        if not own.any():
            continue
        picked = np.full(len(form), -1, dtype=np.int64)
        picked[corner[own]] = values[own] - 1
        back = np.flatnonzero(picked < -1)
        if len(back):  # relative index: count the elements defined above the line
            line = face_lines[np.repeat(np.arange(len(sizes)), sizes)[back]]
            picked[back] += 1 + np.cumsum(kind == element)[line]
            relative[which] = back
        absolute = np.ones(len(picked), dtype=bool)
        absolute[back] = False
        rest = picked[absolute]
        corners[which] = picked
        bounds[which] = (int(rest.min()), int(rest.max())) if len(rest) else (0, -1)
    return sizes, corners, relative, bounds, _slash_count(layout)


def _require_statement(tokens: Tokens, path, lines: np.ndarray, offset: int) -> None:
    """MeshError unless one of ``lines`` (a chunk's non-blank lines, none of them v/vt/vn/f)
    opens with an OBJ keyword; looked at until the first that does."""
    for line in lines:
        if tokens.text(tokens.first[line]) in _OBJ_KEYWORDS:
            return
    size = int(tokens.end[lines[-1]] - tokens.begin[lines[0]])
    raise MeshError(path, int(tokens.number[lines[0]]),
                    f"no OBJ statement in the {size:,} bytes at offset {offset + int(tokens.begin[lines[0]]) - PAD:,}:"
                    f" not an OBJ file")


def _statement(tokens: Tokens, path, line, faces_before, part: _Part) -> None:
    """Handle one rare line: ``g``/``o``/``usemtl`` become events (``mtllib`` lines are read from the
    file's bytes with the resources, :func:`affinity.loaders.resources.mtllib_statements`)."""
    number = int(tokens.number[line])
    raw = uncommented(bytes(tokens.buf[tokens.begin[line] : tokens.end[line]]).split())
    words = [_name_text(word) for word in raw]
    if not words or not _KEYWORD.fullmatch(words[0]):
        raise MeshError(path, number, f"not an OBJ statement: {' '.join(words)!r}")
    name = " ".join(words[1:])
    if words[0] in ("g", "o", "usemtl"):
        part.events.append((faces_before, words[0], name))


def _name_text(word: bytes) -> str:
    """A name as text: UTF-8 when it is, else Latin-1 (exporters write names in
    the system's 8-bit code page; a name never makes a file unreadable)."""
    try:
        return word.decode("utf-8")
    except UnicodeDecodeError:
        return word.decode("latin-1")


class _Progress:
    """How far the assembly is through the file: bytes before and after the chunk being added."""

    def __init__(self, total: int):
        self.total = total
        self.before = 0
        self.after = 0


class _Growing:
    """An array filled block by block: a 1-D array, or rows of ``width`` numbers stored by
    component ((width, capacity): component d of row i at [d, i]).

    When full, the capacity grows to a quarter more than the rows expected by
    the end of the file (extrapolated from the rows per byte since the first
    block), so a file of one kind of content after the other costs one or two
    copies; :meth:`array` is a view of the filled rows, and the capacity beyond
    them is never written, so it stays virtual memory. Rows may widen
    (``v`` lines gaining colours): narrower rows are NaN-padded.
    """

    def __init__(self, dtype, progress: _Progress, width: int | None = None):
        self.dtype = dtype
        self.progress = progress
        self.width = width
        self.size = 0
        self.first_byte = None  # file offset of the chunk that brought the first rows
        self.data = np.empty((0,) if width is None else (width, 0), dtype)

    @property
    def capacity(self) -> int:
        return self.data.shape[-1]

    def __len__(self) -> int:
        return self.size

    def _grown_capacity(self, needed: int) -> int:
        progress = self.progress
        if self.first_byte is None:
            self.first_byte = progress.before
        rate = needed / max(progress.after - self.first_byte, 1)
        expected = needed + rate * max(progress.total - progress.after, 0)
        return int(max(needed, 1.25 * expected, 1 << 12))

    def _reserve(self, rows: int, width: int | None) -> None:
        needed = self.size + rows
        wider = width is not None and width > self.width
        if needed <= self.capacity and not wider:
            return
        capacity = self._grown_capacity(needed) if needed > self.capacity else self.capacity
        if width is None:
            data = np.empty(capacity, self.dtype)
            data[: self.size] = self.data[: self.size]
        else:
            self.width = max(width, self.width)
            data = np.empty((self.width, capacity), self.dtype)
            data[: len(self.data), : self.size] = self.data[:, : self.size]
            data[len(self.data) :, : self.size] = np.nan
        self.data = data

    def append(self, block: np.ndarray) -> None:
        """Add ``block``: (n,) values, or (width, n) rows by component."""
        width = None if self.width is None else block.shape[0]
        self._reserve(block.shape[-1], width)
        end = self.size + block.shape[-1]
        if width is None or width == self.width:
            self.data[..., self.size : end] = block
        else:
            self.data[:width, self.size : end] = block
            self.data[width:, self.size : end] = np.nan
        self.size = end

    def fill(self, rows: int, value) -> None:
        self._reserve(rows, None)
        self.data[self.size : self.size + rows] = value
        self.size += rows

    def array(self) -> np.ndarray:
        """The filled rows: (size,), or (size, width) (a view of the storage by component)."""
        return self.data[: self.size] if self.width is None else self.data[:, : self.size].T


class _Assembly:
    """The mesh's arrays, grown chunk by chunk in file order (see :func:`load_obj`)."""

    def __init__(self, total_bytes: int):
        self.progress = _Progress(total_bytes)
        self.elements = {k: self._growing(np.float64, width=0) for k in _WIDTHS}
        self.face_line = self._growing(np.int64)
        self.sizes = self._growing(np.int64)  # filled only once faces of differing sizes appear
        self.uniform_size = None  # the one face size while every face so far has it
        self.spelled_out = False  # faces of differing sizes appeared: ``sizes`` holds every face's
        self.n_faces = 0
        self.n_corners = 0
        self.n_lines = 0  # lines of the chunks added so far
        self.corners = [None, None, None]  # slot -> _Growing, once a chunk has the slot
        self.twins = set()  # slots whose indices so far are the vertex slot's: its array serves them
        self.bounds = [(0, -1)] * 3
        self.events = []
        self.nan_colors = []  # (vertices, line) with a NaN colour, in file order
        self.mtllib = False  # some chunk may hold an mtllib statement

    def _growing(self, dtype, width=None) -> _Growing:
        return _Growing(dtype, self.progress, width)

    def result(self, future) -> _Part:
        """The part a worker parsed, its line numbers made absolute (the chunk's
        own count from 1: only here is the number of lines before it known)."""
        try:
            part = future.result()
        except MeshError as error:
            raise MeshError(error.path, error.line + self.n_lines * (error.line > 0), error.reason) from None
        part.face_line += self.n_lines
        part.nan_colors = [(count, line + self.n_lines) for count, line in part.nan_colors]
        return part

    def add(self, part: _Part) -> None:
        self.progress.before = self.progress.after
        self.progress.after += part.bytes
        self.n_lines += part.lines
        before = {k: len(self.elements[k]) for k in _WIDTHS}
        for k in _WIDTHS:
            self.elements[k].append(part.elements[k])
        self.nan_colors += part.nan_colors
        self.mtllib |= part.mtllib
        n_faces = len(part.face_line)
        if n_faces == 0:
            self.events += [(face + self.n_faces, key, name) for face, key, name in part.events]
            return
        n_corners = self._add_sizes(part.face_sizes, n_faces)
        for which in range(3):
            self._add_slot(which, part, n_corners, before[_ELEMENT_OF_SLOT[which]])
        self.face_line.append(part.face_line)
        self.events += [(face + self.n_faces, key, name) for face, key, name in part.events]
        self.n_faces += n_faces
        self.n_corners += n_corners

    def _add_slot(self, which: int, part: _Part, n_corners: int, elements_before: int) -> None:
        """Append the part's ``n_corners`` indices of slot ``which`` (the vertex slot's first)."""
        index = part.corners[which]
        twin = which > 0 and index is not None and index is part.corners[0]
        if which in self.twins:
            if twin:
                self._widen_bounds(which, *part.bounds[which])
                return
            self.twins.discard(which)  # the slot parts from the vertex slot: it gets its own array
            self.corners[which] = self._growing(np.int64)
            self.corners[which].append(self.corners[0].array()[: self.n_corners])
        if index is None:
            if self.corners[which] is not None:
                self.corners[which].fill(n_corners, -1)
                self._widen_bounds(which, -1, -1)
            return
        if twin and self.n_corners == 0:
            self.twins.add(which)
            self.bounds[which] = part.bounds[which]
            return
        if self.corners[which] is None:
            self.corners[which] = self._growing(np.int64)
            self.corners[which].fill(self.n_corners, -1)
            if self.n_corners:
                self.bounds[which] = (-1, -1)
        low, high = part.bounds[which]
        back = part.relative[which]
        if back is not None and len(back):
            index[back] += elements_before
            index[back[index[back] < 0]] = -2  # counted back past the first element
            low, high = min(low, int(index[back].min())), max(high, int(index[back].max()))
        self.corners[which].append(index)
        self._widen_bounds(which, low, high)

    def _widen_bounds(self, which: int, low: int, high: int) -> None:
        self.bounds[which] = (min(self.bounds[which][0], low), max(self.bounds[which][1], high))

    def _add_sizes(self, sizes, n_faces: int) -> int:
        """Record the chunk's face sizes; return its number of corners."""
        if isinstance(sizes, int) and not self.spelled_out and self.uniform_size in (None, sizes):
            self.uniform_size = sizes
            return sizes * n_faces
        if not self.spelled_out:  # the first face of another size: spell the sizes out
            self.sizes.fill(self.n_faces, self.uniform_size or 0)
            self.uniform_size = None
            self.spelled_out = True
        if isinstance(sizes, int):
            self.sizes.fill(n_faces, sizes)
            return sizes * n_faces
        self.sizes.append(sizes)
        return int(sizes.sum())

    def face_start(self) -> np.ndarray:
        if not self.spelled_out:
            size = self.uniform_size or 0
            return np.arange(0, size * self.n_faces + 1, max(size, 1))[: self.n_faces + 1]
        face_start = np.empty(self.n_faces + 1, dtype=np.int64)
        face_start[0] = 0
        np.cumsum(self.sizes.array(), out=face_start[1:])
        return face_start

    def mesh(self, path, resources: list) -> Mesh:
        elements = {k: self.elements[k].array() for k in _WIDTHS}
        elements = {k: v if v.shape[1] else v.reshape(0, _WIDTHS[k][0]) for k, v in elements.items()}
        if len(elements[_V]) == 0 and self.n_faces == 0:
            raise MeshError(path, 0, "empty file (no vertices or faces)")
        face_start = self.face_start()
        face_line = self.face_line.array()
        corners = []
        for which, name in enumerate(_SLOT_NAMES):
            total = len(elements[_ELEMENT_OF_SLOT[which]])
            grown = self.corners[which]
            if which in self.twins:
                index = corners[0]  # the same array: OFF and PLY meshes share theirs alike
            elif grown is None:  # no face names this slot: every corner lacks it
                corners.append(np.full(self.n_corners, -1, dtype=np.int64) if total or which == 0 else None)
                continue
            else:
                index = grown.array()
            low, high = self.bounds[which]
            if low < -1 or high >= total:
                check_indices(path, index, total, face_start, face_line, name, absent=-1)
            corners.append(index)

        vertices, texcoords, normals = elements[_V], elements[_VT], elements[_VN]
        group_names, face_group = _groups(self.events, self.n_faces)
        material_names, face_material = _materials(self.events, self.n_faces)
        notes = []
        if self.nan_colors:
            notes.append(color_note(sum(count for count, _ in self.nan_colors), 0, self.nan_colors[0][1]))
        return Mesh(
            path=os.fspath(path),
            positions=vertices[:, :3],  # by component underneath, as the lint gathers them (affinity.lint.CornerTables)
            face_start=face_start,
            corner_vertex=corners[0],
            face_line=face_line,
            texcoords=_texcoords(texcoords) if len(texcoords) else None,
            corner_texcoord=corners[1] if len(texcoords) else None,
            normals=normals if len(normals) else None,
            corner_normal=corners[2] if len(normals) else None,
            colors=np.nan_to_num(vertices[:, 3:6], nan=1.0) if vertices.shape[1] >= 6 and not notes else None,
            group_names=group_names,
            face_group=face_group,
            material_names=material_names,
            face_material=face_material,
            material_textures=_diffuse_textures(resources),
            material_maps=obj_material_maps(resources),
            resources=resources,
            notes=notes,
        )


def _diffuse_textures(resources: list) -> dict[str, str]:
    """Material -> ``map_Kd`` path: the first library naming a material wins, and within a
    library its last ``map_Kd`` (as a renderer reads the libraries in order)."""
    by_library: dict[str, dict[str, str]] = {}  # one pass over the maps: linear in the mtllib lines
    for r in resources:
        if r.role == "map_Kd":
            by_library.setdefault(r.library, {})[r.material] = r.path
    textures: dict[str, str] = {}
    for library in (r for r in resources if r.role == "mtllib"):
        for material, texture in by_library.get(library.name, {}).items():
            textures.setdefault(material, texture)
    return textures


def _texcoords(vt: np.ndarray) -> np.ndarray:
    """(T, 2) float64 (u, v) from ``vt u [v [w]]`` rows (NaN-padded where a
    line has fewer numbers than the widest); a missing v is 0."""
    if vt.shape[1] == 2 and not np.isnan(vt[:, 1]).any():
        return vt
    uv = np.zeros((len(vt), 2))
    uv[:, : min(2, vt.shape[1])] = vt[:, :2]
    return np.nan_to_num(uv, nan=0.0)


def _groups(events, n_faces):
    """Group names (the ``g`` name, else the ``o`` name) and (F,) int32 index per face.

    Only groups that own faces are listed, in order of their first face.
    """
    changes = [(0, "")]
    obj, group = "", ""
    for face, key, name in events:
        if key == "o":
            obj, group = name, ""
        elif key == "g":
            group = name
        if key != "usemtl":
            changes.append((face, group or obj))
    lengths = np.diff([face for face, _ in changes] + [n_faces])
    names, index = _index_changes([c for c, length in zip(changes, lengths) if length > 0], n_faces)
    return names or [""], index


def _materials(events, n_faces):
    """Material names in order of first ``usemtl`` and (F,) int32 index per face (-1: none)."""
    return _index_changes([(0, None)] + [(face, name) for face, key, name in events if key == "usemtl"], n_faces)


def _index_changes(changes, n_faces):
    """Turn ``(first face, name)`` changes (sorted by face) into names and a (F,) int32
    name index per face. A ``None`` name maps to -1."""
    names: dict[str, int] = {}
    codes = [-1 if name is None else names.setdefault(name, len(names)) for _, name in changes]
    lengths = np.diff([face for face, _ in changes] + [n_faces])
    return list(names), np.repeat(np.array(codes, dtype=np.int32), lengths)
