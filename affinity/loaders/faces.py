"""Small array helpers shared by the loaders: ragged lists and index checks."""

from __future__ import annotations

import os

import numpy as np

from ..errors import MeshError
from ..mesh import Mesh


def ragged_positions(starts: np.ndarray, sizes: np.ndarray, stride: int = 1) -> np.ndarray:
    """Positions ``starts[r] + stride * k`` for ``k < sizes[r]``, row after row.

    starts, sizes : (R,) int64; returns (sizes.sum(),) int64.

    >>> ragged_positions(np.array([10, 20]), np.array([2, 3])).tolist()
    [10, 11, 20, 21, 22]
    """
    sizes = np.asarray(sizes, dtype=np.int64)
    if len(sizes) and sizes.min() == sizes.max():  # one size: a broadcast, no repeat
        return (starts[:, None] + stride * np.arange(sizes[0])).ravel()
    before = np.cumsum(sizes) - sizes
    return np.repeat(starts - stride * before, sizes) + stride * np.arange(before[-1] + sizes[-1] if len(sizes) else 0)


def check_indices(path, index: np.ndarray, total: int, face_start, face_line, name: str,
                  absent: int | None = None) -> None:
    """MeshError at the face line of the first corner whose ``index`` is outside [0, total).

    index : (C,) int64 per corner (``absent`` marks a corner without one);
    face_start : (F + 1,) int64; face_line : (F,) int64.
    """
    low = 0 if absent is None else absent
    if len(index) == 0 or (index.min() >= low and index.max() < total):
        return
    corner = int(np.argmax(((index < 0) & (index != absent)) | (index >= total)))
    face = np.searchsorted(face_start, corner, side="right") - 1
    raise MeshError(path, int(face_line[face]), f"{name} index out of range (the file has {total})")


def whole_indices(values: np.ndarray, invalid: int = -1) -> np.ndarray:
    """(C,) int64 indices from list items as read: an item that is no whole number (2.5; NaN, inf and
    1e30 from text or float lists) becomes ``invalid``, for :func:`check_indices` to report."""
    values = np.asarray(values)
    if values.dtype.kind in "iub":
        return values.astype(np.int64)
    whole = (values == np.round(values)) & (np.abs(values) < 2**62)
    return np.where(whole, values, invalid).astype(np.int64)


def unit_colors(path, colors: np.ndarray, scale: float, lines, notes: list) -> np.ndarray | None:
    """(V, 3) float64 colours divided by ``scale``; MeshError where one leaves [0, 1].

    lines : (V,) int64 source line per vertex, or an int for all (0 in binary files).
    A NaN colour is no colour: the mesh is checked without colours (None), and
    ``notes`` says so once.
    """
    colors = colors / scale
    missing = np.isnan(colors).any(axis=1)
    if missing.any():
        vertex = int(np.argmax(missing))
        line = lines if np.isscalar(lines) else int(lines[vertex])
        notes.append(color_note(int(missing.sum()), vertex, line))
        return None
    outside = ~((colors >= 0) & (colors <= 1)).all(axis=1)
    if outside.any():
        vertex = int(np.argmax(outside))
        line = lines if np.isscalar(lines) else int(lines[vertex])
        raise MeshError(path, line, f"vertex colour {colors[vertex] * scale} outside the range [0, {scale:g}]")
    return colors


def color_note(count: int, vertex: int, line: int) -> str:
    """The note for a mesh whose vertex colours are dropped because ``count`` of them are NaN."""
    where = f"line {line}" if line else f"vertex {vertex}"
    return f"{count} vertex colour{'s' * (count != 1)} NaN (first at {where}): colours not checked"


def polygon_mesh(path, positions, sizes, corners, face_line, texcoords=None, corner_texcoord=None, normals=None,
                 colors=None) -> Mesh:
    """A :class:`Mesh` from per-vertex attributes and face lists as OFF and PLY store them.

    positions : (V, 3); sizes : (F,) int64 corners per face; corners : (C,) vertex
    indices as read (floats from text are checked to be whole); face_line : (F,) int64.
    texcoords (T, 2) are per vertex unless ``corner_texcoord`` (C,) says otherwise;
    normals (V, 3) and colors (V, 3) are per vertex. Faces with fewer than three
    corners and indices outside the vertices raise MeshError at the face's line.
    """
    small = sizes < 3
    if small.any():
        raise MeshError(path, int(face_line[np.argmax(small)]),
                        f"face with {sizes[small][0]} corners (at least 3 needed)")
    face_start = np.concatenate(([0], np.cumsum(sizes)))
    corner_vertex = whole_indices(corners)
    check_indices(path, corner_vertex, len(positions), face_start, face_line, "vertex")
    if texcoords is not None and corner_texcoord is None:
        corner_texcoord = corner_vertex
    return Mesh(
        path=os.fspath(path),
        positions=np.asarray(positions, dtype=np.float64),
        face_start=face_start,
        corner_vertex=corner_vertex,
        face_line=np.asarray(face_line, dtype=np.int64),
        texcoords=texcoords,
        corner_texcoord=corner_texcoord,
        normals=normals,
        corner_normal=None if normals is None else corner_vertex,
        colors=colors,
    )
