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
from .text import read_rows

_KEYWORD = re.compile(rb"(ST)?(C)?(N)?OFF")


def load_off(path) -> Mesh:
    """Read an ASCII OFF file."""
    with open(path, "rb") as fh:
        line, prefix, counts = _header(fh, path)
        rows = read_rows(fh, path, line + 1)
    has_st, has_color, has_normal = (bool(p) for p in prefix.groups())
    n_vertices, n_faces = counts
    if len(rows.number) < n_vertices + n_faces:
        last = int(rows.number[-1]) if len(rows.number) else line
        raise MeshError(path, last, f"truncated: {len(rows.number)} data lines for {n_vertices} vertices and {n_faces} faces")
    if len(rows.number) > n_vertices + n_faces:
        raise MeshError(path, int(rows.number[n_vertices + n_faces]), "more data lines than the header declares")

    width = rows.counts[:n_vertices]
    fixed = 3 + 3 * has_normal + 2 * has_st
    wrong = ~np.isin(width - fixed, (3, 4) if has_color else (0,))
    if wrong.any():
        row = int(np.argmax(wrong))
        raise MeshError(path, int(rows.number[row]), f"vertex line has {width[row]} numbers")
    first = rows.first[:n_vertices]
    vertex_values = rows.values[: rows.first[n_vertices]]
    infinite = ~np.isfinite(vertex_values)
    if infinite.any():
        row = np.searchsorted(rows.first, np.argmax(infinite), side="right") - 1
        raise MeshError(path, int(rows.number[row]), "coordinate is not finite")

    def columns(offset, count):
        return rows.values[first[:, None] + offset + np.arange(count)]

    positions = columns(0, 3)
    normals = columns(3, 3) if has_normal else None
    colors = None
    if has_color:
        colors = columns(3 + 3 * has_normal, 3)
        colors = unit_colors(path, colors, 255.0 if (colors > 1).any() else 1.0, rows.number[:n_vertices])
    texcoords = rows.values[(first + width - 2)[:, None] + np.arange(2)] if has_st else None

    face_rows = np.arange(n_vertices, n_vertices + n_faces)
    face_line = rows.number[face_rows]
    sizes = rows.values[rows.first[face_rows]]
    extra = rows.counts[face_rows] - 1 - sizes
    bad = (sizes < 3) | (sizes != np.round(sizes)) | (extra < 0) | (extra > 4)
    if bad.any():
        row = int(np.argmax(bad))
        raise MeshError(path, int(face_line[row]), f"face line: {rows.counts[face_rows][row]} numbers for a face of {sizes[row]:g} corners")
    sizes = sizes.astype(np.int64)
    corners = rows.values[ragged_positions(rows.first[face_rows] + 1, sizes)]
    return polygon_mesh(path, positions, sizes, corners, face_line, texcoords, None, normals, colors)


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
                raise MeshError(path, line, f"not an OFF file: header {words[0][:20]!r} (supported: OFF, COFF, NOFF, STOFF and combinations)")
            words = words[1:]
        numbers += words
    try:
        counts = [int(word) for word in numbers[:3]]
    except ValueError:
        raise MeshError(path, line, f"bad counts {b' '.join(numbers).decode('latin-1')!r}") from None
    if len(numbers) > 3 or min(counts) < 0:
        raise MeshError(path, line, f"bad counts {b' '.join(numbers).decode('latin-1')!r}")
    return line, prefix, (counts[0], counts[1])
