"""The assembly phase of the OBJ reader: the chunks' parts, added in file order, become the mesh.

Relative indices that count back past their chunk are resolved here (the elements before
the chunk are known only now), and every index is range-checked against the whole file.
"""

from __future__ import annotations

import os

import numpy as np

from ...errors import MeshError
from ...mesh import Mesh
from ..faces import check_indices, color_note
from ..mtl import obj_material_maps
from .faces import count_back
from .scan import ELEMENT_OF_SLOT, SLOT_NAMES, VN, VT, WIDTHS, Part, V


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


class Assembly:
    """The mesh's arrays, grown chunk by chunk in file order (see :func:`affinity.loaders.obj.load_obj`)."""

    def __init__(self, total_bytes: int):
        self.progress = _Progress(total_bytes)
        self.elements = {k: self._growing(np.float64, width=0) for k in WIDTHS}
        # a file has at most one line more than it has bytes: int32 holds every line of one under 2 GiB
        self.face_line = self._growing(np.int32 if total_bytes < 1 << 31 else np.int64)
        self.size_runs = []  # per part with faces: (faces, corners of each) or (F,) int64 sizes
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

    def result(self, future) -> Part:
        """The part a worker parsed, its line numbers made absolute (the chunk's
        own count from 1: only here is the number of lines before it known)."""
        try:
            part = future.result()
        except MeshError as error:
            raise MeshError(error.path, error.line + self.n_lines * (error.line > 0), error.reason) from None
        part.face_line += self.n_lines
        part.nan_colors = [(count, line + self.n_lines) for count, line in part.nan_colors]
        return part

    def add(self, part: Part) -> None:
        self.progress.before = self.progress.after
        self.progress.after += part.bytes
        self.n_lines += part.lines
        before = {k: len(self.elements[k]) for k in WIDTHS}
        for k in WIDTHS:
            self.elements[k].append(part.elements[k])
        self.nan_colors += part.nan_colors
        self.mtllib |= part.mtllib
        n_faces = len(part.face_line)
        if n_faces == 0:
            self.events += [(face + self.n_faces, key, name) for face, key, name in part.events]
            return
        n_corners = self._add_sizes(part.face_sizes, n_faces)
        for which in range(3):
            self._add_slot(which, part, n_corners, before[ELEMENT_OF_SLOT[which]])
        self.face_line.append(part.face_line)
        self.events += [(face + self.n_faces, key, name) for face, key, name in part.events]
        self.n_faces += n_faces
        self.n_corners += n_corners

    def _add_slot(self, which: int, part: Part, n_corners: int, elements_before: int) -> None:
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
        if back is not None:
            back_low, back_high = count_back(index, back, elements_before)
            if back_low < 0:  # counted back past the first element: out of range, not absent (-1)
                index[back[index[back] < 0]] = back_low = -2
            low, high = min(low, back_low), max(high, back_high)
        self.corners[which].append(index)
        self._widen_bounds(which, low, high)

    def _widen_bounds(self, which: int, low: int, high: int) -> None:
        self.bounds[which] = (min(self.bounds[which][0], low), max(self.bounds[which][1], high))

    def _add_sizes(self, sizes, n_faces: int) -> int:
        """Record the chunk's face sizes; return its number of corners."""
        if isinstance(sizes, np.ndarray):
            self.size_runs.append(sizes)
            return int(sizes.sum())
        self.size_runs.append((n_faces, sizes))
        return sizes * n_faces

    def face_start(self) -> np.ndarray:
        """(F + 1,) int64 first corner of every face."""
        runs = self.size_runs
        uniform = {run[1] if isinstance(run, tuple) else None for run in runs}
        if len(uniform) <= 1 and None not in uniform:
            size = runs[0][1] if runs else 0  # every face has this size: no per-face array
            return np.arange(0, size * self.n_faces + 1, max(size, 1))[: self.n_faces + 1]
        face_start = np.empty(self.n_faces + 1, dtype=np.int64)
        face_start[0] = 0
        sizes = [np.full(run[0], run[1], np.int64) if isinstance(run, tuple) else run for run in runs]
        np.cumsum(np.concatenate(sizes), out=face_start[1:])
        return face_start

    def mesh(self, path, resources: list) -> Mesh:
        elements = {k: self.elements[k].array() for k in WIDTHS}
        elements = {k: v if v.shape[1] else v.reshape(0, WIDTHS[k][0]) for k, v in elements.items()}
        if len(elements[V]) == 0 and self.n_faces == 0:
            raise MeshError(path, 0, "empty file (no vertices or faces)")
        face_start = self.face_start()
        face_line = self.face_line.array()
        corners = []
        for which, name in enumerate(SLOT_NAMES):
            total = len(elements[ELEMENT_OF_SLOT[which]])
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

        vertices, texcoords, normals = elements[V], elements[VT], elements[VN]
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
    """Group names (the ``g`` name, else the ``o`` name) and (F,) index per face (:func:`_index_changes`).

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
    """Material names in order of first ``usemtl`` and (F,) index per face (-1: none; :func:`_index_changes`)."""
    return _index_changes([(0, None)] + [(face, name) for face, key, name in events if key == "usemtl"], n_faces)


def _index_changes(changes, n_faces):
    """Turn ``(first face, name)`` changes (sorted by face) into names and a (F,) name index per
    face, of the narrowest signed integer type that holds -1 and every index (int8 up to 127 names:
    a file of 10 million one-triangle faces spends 10 MB on each table, not 40). A ``None`` name maps
    to -1."""
    names: dict[str, int] = {}
    codes = [-1 if name is None else names.setdefault(name, len(names)) for _, name in changes]
    lengths = np.diff([face for face, _ in changes] + [n_faces])
    return list(names), np.repeat(np.array(codes, dtype=np.min_scalar_type(-max(len(names), 1))), lengths)

