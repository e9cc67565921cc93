"""Geomview OFF reader: ``[ST][C][N]OFF`` headers, '#' comments, counts on the
keyword line or the next one, one vertex or face per line.

Vertex lines are ``x y z [nx ny nz] [r g b [a]] [s t]``; colours are 0-255
integers or 0-1 floats (any component above 1 means the 0-255 scale). Face
lines are ``n i0 ... i(n-1) [colour]``; face colours are ignored.
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import MeshError
from ..mesh import Mesh
from .faces import polygon_mesh, ragged_positions, unit_colors
from .numbers import out_of_range, out_of_range_reason
from .regular import open_regular
from .text import read_rows

_KEYWORD = re.compile(rb"(ST)?(C)?(N)?OFF")


def load_off(path) -> Mesh:
    """Read an ASCII OFF file."""
    with open_regular(path) as fh:
        line, prefix, counts = _header(fh, path)
        rows = read_rows(fh, path, line + 1)
    has_st, has_color, has_normal = (bool(p) for p in prefix.groups())
    n_vertices, n_faces = counts
    if len(rows.number) < n_vertices + n_faces:
        last = int(rows.number[-1]) if len(rows.number) else line
        raise MeshError(path, last,
                        f"truncated: {len(rows.number)} data lines for {n_vertices} vertices and {n_faces} faces")

    width = rows.counts[:n_vertices]
    fixed = 3 + 3 * has_normal + 2 * has_st
    wrong = ~np.isin(width - fixed, (3, 4) if has_color else (0,))
    if wrong.any():
        row = int(np.argmax(wrong))
        raise MeshError(path, int(rows.number[row]), f"vertex line has {width[row]} numbers")
    first = rows.first[:n_vertices]
    vertex_values = rows.values[: rows.first[n_vertices]]
    infinite = out_of_range(vertex_values)
    if infinite.any():
        row = np.searchsorted(rows.first, np.flatnonzero(infinite), side="right") - 1
        column = np.flatnonzero(infinite) - first[row]
        colour = 3 + 3 * has_normal
        # a NaN colour drops the colours (unit_colors says so); anything else must be finite
        allowed = (has_color & (column >= colour) & (column < width[row] - 2 * has_st)
                   & np.isnan(vertex_values[infinite]))
        if not allowed.all():
            value = vertex_values[infinite][np.argmax(~allowed)]
            raise MeshError(path, int(rows.number[row[np.argmax(~allowed)]]),
                            out_of_range_reason(value) if np.isfinite(value) else "coordinate is not finite")

    def columns(offset, count):
        return rows.values[first[:, None] + offset + np.arange(count)]

    positions = columns(0, 3)
    normals = columns(3, 3) if has_normal else None
    colors, notes = None, []
    if has_color:
        colors = columns(3 + 3 * has_normal, 3)
        colors = unit_colors(path, colors, 255.0 if (colors > 1).any() else 1.0, rows.number[:n_vertices], notes)
    texcoords = rows.values[(first + width - 2)[:, None] + np.arange(2)] if has_st else None

    face_rows = np.arange(n_vertices, n_vertices + n_faces)
    face_line = rows.number[face_rows]
    sizes = rows.values[rows.first[face_rows]]
    extra = rows.counts[face_rows] - 1 - sizes
    bad = (sizes < 3) | (sizes != np.round(sizes)) | (extra < 0) | (extra > 4)
    if len(rows.number) > n_vertices + n_faces or bad.any():
        sizes, starts, face_line = _free_format_faces(path, rows, n_vertices, n_faces)
    else:
        sizes, starts = sizes.astype(np.int64), rows.first[face_rows] + 1
    corners = rows.values[ragged_positions(starts, sizes)]
    mesh = polygon_mesh(path, positions, sizes, corners, face_line, texcoords, None, normals, colors)
    mesh.notes += notes
    return mesh


def _free_format_faces(path, rows, n_vertices: int, n_faces: int):
    """Faces read as a stream of numbers: ``n i0 ... i(n-1)`` may wrap over lines, and
    what follows the last index on its line (0 to 4 numbers) is the face's colour.

    Returns ``sizes (F,) int64``, ``starts (F,) int64`` (offset of each face's first
    index in ``rows.values``) and ``face_line (F,) int64`` (the line of its count).
    Each face's place depends on the sizes before it, so this walks the faces
    one by one; files with one face a line take the vectorized path instead.
    """
    first = int(rows.first[n_vertices])
    values = rows.values
    token_line = np.repeat(rows.number, rows.counts)
    sizes, starts, face_line = (np.empty(n_faces, dtype=np.int64) for _ in range(3))
    at = first
    for face in range(n_faces):
        if at >= len(values):
            raise MeshError(path, int(token_line[-1]), f"truncated: {face} of {n_faces} faces")
        size = values[at]
        if not (3 <= size < 2**31 and size == round(size)):
            raise MeshError(path, int(token_line[at]), f"face {face}: {size:g} is not a number of corners (at least 3)")
        end = at + 1 + int(size)
        if end > len(values):
            raise MeshError(path, int(token_line[-1]), f"truncated: face {face} needs {int(size)} indices")
        sizes[face], starts[face], face_line[face] = size, at + 1, token_line[at]
        at = end
        colour = np.searchsorted(token_line, token_line[end - 1], side="right")  # the rest of that line
        if colour - at > 4:
            raise MeshError(path, int(token_line[end - 1]), f"face {face}: {colour - at} numbers after its indices")
        at = colour
    if at < len(values):
        raise MeshError(path, int(token_line[at]), "more data than the header declares")
    return sizes, starts, face_line


def _header(fh, path):
    """Read the keyword and counts lines; return (last header line number, keyword match, (V, F))."""
    numbers: list[bytes] = []
    prefix = None
    line = 0
    while len(numbers) < 2:
        raw = fh.readline()
        if not raw:
            raise MeshError(path, line, "truncated header: expected the vertex and face counts")
        line += 1
        words = raw.split(b"#", 1)[0].split()
        if not words:
            continue
        if prefix is None:
            prefix = _KEYWORD.fullmatch(words[0])
            if prefix is None:
                raise MeshError(path, line, f"not an OFF file: header {words[0][:20]!r} "
                                            "(supported: OFF, COFF, NOFF, STOFF and combinations)")
            words = words[1:]
        numbers += words
    try:
        counts = [int(word) for word in numbers[:3]]
    except ValueError:
        raise MeshError(path, line, f"bad counts {b' '.join(numbers).decode('latin-1')!r}") from None
    if len(numbers) > 3 or min(counts) < 0:
        raise MeshError(path, line, f"bad counts {b' '.join(numbers).decode('latin-1')!r}")
    return line, prefix, (counts[0], counts[1])
