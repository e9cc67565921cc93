"""Wavefront OBJ reader, vectorized over lines and corners.

Each chunk of lines is tokenized once at whitespace and '/'. Lines are
classified by their keyword token (``v``, ``vt``, ``vn``, ``f``); the numbers of
all lines of one kind are parsed in one call and reshaped by their per-line
counts. A face token's role in its corner (``v``, ``vt`` or ``vn`` slot) follows
from the separator before it: whitespace starts a corner, '/' moves to the next
slot, '//' skips the ``vt`` slot. Statements without bulk (``g``, ``o``,
``usemtl``, ``mtllib``, ``s``, ``l``, ...) are rare and handled one by one.

Indices may be negative (relative to the elements defined so far) and may refer
to elements defined later in the file; every index is range-checked against the
whole file.
"""

from __future__ import annotations

import os
import re
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from ..mesh import Mesh, MeshError
from .faces import check_indices, ragged_positions
from .mtl import read_material_textures
from .numbers import parse_ints
from .text import Tokens, floats_or_raise, read_chunks, tokenize

_V, _VT, _VN, _F = 1, 2, 3, 4
#: Numbers a line of each kind may carry: ``v x y z [w]``, ``v x y z r g b [a]``,
#: ``vt u [v [w]]``, ``vn x y z``.
_WIDTHS = {_V: (3, 4, 6, 7), _VT: (1, 2, 3), _VN: (3,)}
_MAX_WIDTH = 8
#: ``_ALLOWED[kind][min(n, 8)]``: a line of that kind may carry ``n`` numbers.
_ALLOWED = {kind: np.isin(np.arange(_MAX_WIDTH + 1), widths) for kind, widths in _WIDTHS.items()}
_SLASH = ord("/")
_KEYWORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


@dataclass
class _Part:
    """What one chunk contributes; indices are still relative to the chunk.

    ``corners[k]`` is (C,) int64 0-based index for slot ``k`` (vertex, texcoord,
    normal), -1 where the corner lacks it; ``relative[k]`` lists the corners
    whose index counted back from the chunk's own elements and still needs
    the count of elements before the chunk added.
    """

    elements: dict  # kind -> (n, width) float64
    face_sizes: np.ndarray
    face_line: np.ndarray
    corners: list
    relative: list
    events: list = field(default_factory=list)  # (face in chunk, keyword, name)
    mtllibs: list = field(default_factory=list)


#: Chunks parsed in parallel (NumPy releases the GIL inside its loops).
_WORKERS = 2


def load_obj(path) -> Mesh:
    """Read a Wavefront OBJ file (and the ``map_Kd`` entries of its ``mtllib`` files)."""
    parts, pending = [], []
    with open(path, "rb") as fh, ThreadPoolExecutor(_WORKERS) as pool:
        for chunk in read_chunks(fh, continuations=True):
            pending.append(pool.submit(_parse_chunk, chunk, path))
            if len(pending) > 2 * _WORKERS:  # bound the chunks held in memory
                parts.append(pending.pop(0).result())
        parts += [future.result() for future in pending]
    return _assemble(path, parts)


def _parse_chunk(chunk, path) -> _Part:
    tokens = tokenize(chunk, path, slash=True)
    counts = tokens.counts
    kind = _line_kinds(tokens, counts)
    elements = {k: _elements(tokens, path, np.flatnonzero(kind == k), k) for k in _WIDTHS}
    _check_colors(tokens, path, np.flatnonzero(kind == _V), elements[_V])
    face_lines = np.flatnonzero(kind == _F)
    sizes, corners, relative = _faces(tokens, path, kind, face_lines)
    part = _Part(
        elements=elements,
        face_sizes=sizes,
        face_line=tokens.number[face_lines],
        corners=corners,
        relative=relative,
    )
    statements = np.flatnonzero((counts > 0) & (kind == 0))
    if len(statements):
        faces_before = np.cumsum(kind == _F)
        for line in statements:
            _statement(tokens, path, line, int(faces_before[line]), part)
    return part


def _line_kinds(tokens: Tokens, counts) -> np.ndarray:
    """(L,) int8 kind of every line from its keyword token; 0 for anything else."""
    buf = tokens.buf
    kind = np.zeros(len(counts), dtype=np.int8)
    if len(tokens.starts) == 0:
        return kind
    keyword = np.minimum(tokens.first[:-1], len(tokens.starts) - 1)
    start = tokens.starts[keyword]
    length = np.where(counts > 0, tokens.ends[keyword] - start, 0)
    first, second = buf[start], buf[start + 1]
    kind[(length == 1) & (first == ord("v"))] = _V
    kind[(length == 2) & (first == ord("v")) & (second == ord("t"))] = _VT
    kind[(length == 2) & (first == ord("v")) & (second == ord("n"))] = _VN
    kind[(length == 1) & (first == ord("f"))] = _F
    return kind


def _line_tokens(tokens: Tokens, lines):
    """Tokens after the keyword of ``lines``: per-line count (n,) and indices (sum,) int64."""
    width = tokens.counts[lines] - 1
    return width, ragged_positions(tokens.first[lines] + 1, width)


def _elements(tokens: Tokens, path, lines, which) -> np.ndarray:
    """(n, width) float64 numbers of the ``which`` lines, NaN where a line has fewer."""
    width, numbers = _line_tokens(tokens, lines)
    wrong = ~_ALLOWED[which][np.minimum(width, _MAX_WIDTH)]
    if wrong.any():
        line = lines[np.argmax(wrong)]
        raise MeshError(path, tokens.number[line], f"{tokens.text(tokens.first[line])} line with {width[wrong][0]} numbers")
    buf = tokens.buf
    slashed = (buf[tokens.starts[numbers] - 1] == _SLASH) | (buf[tokens.ends[numbers]] == _SLASH)
    if slashed.any():
        token = numbers[np.argmax(slashed)]
        raise MeshError(path, tokens.line_of_token(token), f"unexpected '/' next to {tokens.text(token)!r}")
    values = floats_or_raise(tokens, path, numbers, finite=True)
    if len(width) == 0 or (width == width[0]).all():
        rows = values.reshape(len(width), width[0] if len(width) else _WIDTHS[which][0])
    else:
        rows = np.full((len(width), max(_WIDTHS[which])), np.nan)
        rows[np.repeat(np.arange(len(width)), width), ragged_positions(np.zeros(len(width), np.int64), width)] = values
    if which != _V or rows.shape[1] == 3:
        return rows
    if rows.shape[1] == 4:  # 'v x y z w': w is not a colour
        return rows[:, :3]
    rows[width == 4, 3] = np.nan
    return rows[:, :6]  # the alpha of 'v x y z r g b a' is not kept


def _check_colors(tokens: Tokens, path, lines, vertices) -> None:
    """MeshError at the first ``v x y z r g b`` line whose colour leaves [0, 1]."""
    if vertices.shape[1] < 6:
        return
    outside = ((vertices[:, 3:6] < 0) | (vertices[:, 3:6] > 1)).any(axis=1)
    if outside.any():
        raise MeshError(path, tokens.number[lines[np.argmax(outside)]], "vertex colour outside [0, 1]")


#: Bits of a face token's separator layout (see :func:`_face_layout`).
_AFTER_SLASH, _AFTER_DOUBLE, _BEFORE_SLASH, _BAD_GAP = 1, 2, 4, 8


def _face_layout(buf, start, end, previous_end) -> np.ndarray:
    """(K,) uint8 per face token (bytes ``start:end``, previous token ending at
    ``previous_end``): which of '/', '//' precede it, whether '/' follows, and
    whether the separator before it is anything but whitespace, '/' or '//'."""
    after = buf[start - 1] == _SLASH
    double = after & (buf[start - 2] == _SLASH)
    bad_gap = after & (start - previous_end != 1 + double)
    layout = after.view(np.uint8) | (double.view(np.uint8) << 1) | (bad_gap.view(np.uint8) << 3)
    layout |= (buf[end] == _SLASH).view(np.uint8) << 2
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
    malformed = ((layout & _BAD_GAP) > 0) | (after & line_start) | (slot > 2)
    malformed |= ((layout & _BEFORE_SLASH) > 0) & ~joined_next
    return slot, malformed


def _faces(tokens: Tokens, path, kind, face_lines):
    """Corner structure of the chunk's ``f`` lines.

    Returns ``sizes (F,) int64``, ``corners`` [3 x (C,) int64] and
    ``relative`` [3 x (r,) int64] as described in :class:`_Part`. Blocks of
    face lines with one layout (the usual case: all ``v/vt/vn`` quads) are
    checked as a whole against their first line instead of token by token.
    """
    buf = tokens.buf
    width, index = _line_tokens(tokens, face_lines)
    if len(face_lines) == 0:
        empty = np.zeros(0, np.int64)
        return empty, [empty] * 3, [empty] * 3
    start, end = tokens.starts[index], tokens.ends[index]
    layout = _face_layout(buf, start, end, tokens.ends[index - 1])
    values, bad = parse_ints(buf, start, end)
    if len(bad) or not values.all():
        token = index[np.concatenate([bad, np.flatnonzero(values == 0)]).min()]
        raise MeshError(path, tokens.line_of_token(token), f"bad index {tokens.text(token)!r} (indices start at 1)")
    uniform = width[0] > 0 and (width == width[0]).all() and (layout.reshape(-1, width[0]) == layout[: width[0]]).all()
    if uniform:  # every line is laid out like the first: work out the first line only
        width, layout = width[:1], layout[: width[0]]
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
    if uniform:
        values = values.reshape(len(face_lines), -1)
        sizes = np.repeat(sizes, len(face_lines))

    corners, relative = [], []
    for which, element in enumerate((_V, _VT, _VN)):
        own = slot == which
        if uniform:  # (F, T) values: the slot's columns land in their corners' columns
            picked = np.full((len(face_lines), len(form)), -1, dtype=np.int64)
            picked[:, corner[own]] = values[:, own] - 1
            picked = picked.ravel()
        else:
            picked = np.full(len(form), -1, dtype=np.int64)
            picked[corner[own]] = values[own] - 1
        back = np.flatnonzero(picked < -1)
        if len(back):  # relative index: count the elements defined above the line
            line = face_lines[np.repeat(np.arange(len(sizes)), sizes)[back]]
            picked[back] += 1 + np.cumsum(kind == element)[line]
        corners.append(picked)
        relative.append(back)
    return sizes, corners, relative


def _statement(tokens: Tokens, path, line, faces_before, part: _Part) -> None:
    """Handle one rare line: ``g``/``o``/``usemtl`` become events, ``mtllib`` is kept."""
    number = int(tokens.number[line])
    raw = bytes(tokens.buf[tokens.begin[line] : tokens.end[line]]).split()
    comment = next((k for k, word in enumerate(raw) if word.startswith(b"#")), len(raw))
    try:
        words = [word.decode("utf-8") for word in raw[:comment]]
    except UnicodeDecodeError:
        raise MeshError(path, number, "text is not UTF-8") from None
    if not words or not _KEYWORD.fullmatch(words[0]):
        raise MeshError(path, number, f"not an OBJ statement: {' '.join(words)!r}")
    name = " ".join(words[1:])
    if words[0] in ("g", "o", "usemtl"):
        part.events.append((faces_before, words[0], name))
    elif words[0] == "mtllib":
        part.mtllibs.append(name)


def _assemble(path, parts: list[_Part]) -> Mesh:
    elements = {k: _stack([p.elements[k] for p in parts]) for k in _WIDTHS}
    sizes = np.concatenate([np.zeros(0, np.int64)] + [p.face_sizes for p in parts])
    if len(elements[_V]) == 0 and len(sizes) == 0:
        raise MeshError(path, 0, "empty file (no vertices or faces)")
    face_start = np.concatenate(([0], np.cumsum(sizes)))
    face_line = np.concatenate([np.zeros(0, np.int64)] + [p.face_line for p in parts])
    corner_offset = face_start[np.cumsum([0] + [len(p.face_sizes) for p in parts])]
    corners = []
    for which, (element, name) in enumerate(zip((_V, _VT, _VN), ("vertex", "texture coordinate", "normal"))):
        element_offset = np.cumsum([0] + [len(p.elements[element]) for p in parts])
        index = np.concatenate([np.zeros(0, np.int64)] + [p.corners[which] for p in parts])
        back = np.concatenate([np.zeros(0, np.int64)] + [p.relative[which] + c for p, c in zip(parts, corner_offset)])
        index[back] += np.repeat(element_offset[:-1], [len(p.relative[which]) for p in parts])
        index[back[index[back] < 0]] = -2  # counted back past the first element
        check_indices(path, index, len(elements[element]), face_start, face_line, name, absent=-1)
        corners.append(index)

    vertices, texcoords, normals = elements[_V], elements[_VT], elements[_VN]
    events = [
        (face + offset, key, name)
        for part, offset in zip(parts, np.cumsum([0] + [len(p.face_sizes) for p in parts]))
        for face, key, name in part.events
    ]
    group_names, face_group = _groups(events, len(sizes))
    material_names, face_material = _materials(events, len(sizes))
    folder = os.path.dirname(os.fspath(path))
    textures: dict[str, str] = {}
    for library in (name for p in parts for name in p.mtllibs):
        for material, texture in read_material_textures(os.path.join(folder, library)).items():
            textures.setdefault(material, texture)
    return Mesh(
        path=os.fspath(path),
        positions=np.ascontiguousarray(vertices[:, :3]),
        face_start=face_start,
        corner_vertex=corners[0],
        face_line=face_line,
        texcoords=_texcoords(texcoords) if len(texcoords) else None,
        corner_texcoord=corners[1] if len(texcoords) else None,
        normals=normals if len(normals) else None,
        corner_normal=corners[2] if len(normals) else None,
        colors=np.nan_to_num(vertices[:, 3:6], nan=1.0) if vertices.shape[1] >= 6 else None,
        group_names=group_names,
        face_group=face_group,
        material_names=material_names,
        face_material=face_material,
        material_textures=textures,
    )


def _stack(blocks: list[np.ndarray]) -> np.ndarray:
    """Stack (n_i, w_i) blocks into (sum n_i, max w_i), NaN-padding narrower ones."""
    width = max([b.shape[1] for b in blocks], default=3)
    padded = [np.pad(b, ((0, 0), (0, width - b.shape[1])), constant_values=np.nan) if b.shape[1] < width else b for b in blocks]
    return np.concatenate([np.zeros((0, width))] + padded)


def _texcoords(vt: np.ndarray) -> np.ndarray:
    """(T, 2) float64 (u, v) from ``vt u [v [w]]`` rows; a missing v is 0."""
    if vt.shape[1] == 2:
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
