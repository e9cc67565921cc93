"""Write a fixed OBJ as the input's own bytes with the replaced faces' lines dropped and the rest appended.

Every statement the fix does not change is kept byte for byte and in order: vertex,
texture-coordinate and normal lines, comments, groups, materials, and every face not
replaced. The lines of the replaced faces (refined quads and the transition faces
beside them) are dropped; the new ``v``/``vt``/``vn`` rows and faces are appended at
the end, so no index of an existing line moves (negative, relative indices included).
Before each run of new faces the ``usemtl``, ``g``, ``o`` and ``s`` statements in force
at the face they replace are restated, so they keep its material, group and smoothing.
The new lines end as the file's first line does (``\n`` or ``\r\n``).
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh
from .apply import Refined, corner_slots

#: Statements whose state a face takes from the last one above it, restated before the new faces.
STATE_WORDS = (b"usemtl", b"g", b"o", b"s")


def line_starts(source: bytes) -> np.ndarray:
    """(L + 1,) int64 byte offsets of every line's start, then the end of the bytes (line i, 1-based,
    is ``source[starts[i - 1]:starts[i]]``, its line end included)."""
    ends = np.flatnonzero(np.frombuffer(source, dtype=np.uint8) == ord("\n")) + 1
    if len(ends) == 0 or ends[-1] != len(source):
        ends = np.append(ends, len(source))
    return np.concatenate([[0], ends]).astype(np.int64)


def state_lines(source: bytes, starts: np.ndarray, lines: np.ndarray) -> np.ndarray:
    """(n, 4) int64: for each 1-based line in ``lines`` (n,), the last line above it that states each of
    :data:`STATE_WORDS` (0: none)."""
    data = np.frombuffer(source, dtype=np.uint8)
    width = max(len(w) for w in STATE_WORDS) + 1
    heads = np.zeros((len(starts) - 1, width), dtype=np.uint8)
    for k in range(width):
        at = starts[:-1] + k
        inside = at < starts[1:]
        heads[inside, k] = data[at[inside]]
    found = np.zeros((len(lines), len(STATE_WORDS)), dtype=np.int64)
    numbers = np.arange(1, len(starts))
    for column, word in enumerate(STATE_WORDS):
        stated = (heads[:, : len(word)] == np.frombuffer(word, dtype=np.uint8)).all(axis=1)
        stated &= np.isin(heads[:, len(word)], np.frombuffer(b" \t\r\n", dtype=np.uint8))
        last = np.maximum.accumulate(np.where(stated, numbers, 0))
        found[:, column] = last[lines - 1]
    return found


def _statements(keyword: str, rows: np.ndarray) -> str:
    """``keyword x y ...`` lines of the rows of (k, D) float64, each number its shortest round-trip form."""
    line = keyword + " %r" * rows.shape[1] + "\n"
    return "".join(line % row for row in map(tuple, rows.tolist()))


def _corner_words(fixed: Mesh, corners: np.ndarray) -> np.ndarray:
    """(k,) str ``v``, ``v/vt``, ``v//vn`` or ``v/vt/vn`` (1-based) of the corners ``corners`` (k,) int64."""
    words = (fixed.corner_vertex[corners] + 1).astype(str).astype(object)
    vt = np.full(len(corners), -1) if fixed.corner_texcoord is None else fixed.corner_texcoord[corners]
    vn = np.full(len(corners), -1) if fixed.corner_normal is None else fixed.corner_normal[corners]
    vt_words = np.where(vt >= 0, (vt + 1).astype(str), "").astype(object)
    words = np.where((vt >= 0) | (vn >= 0), words + "/" + vt_words, words)
    return np.where(vn >= 0, words + "/" + (vn + 1).astype(str).astype(object), words)


def _face_lines(fixed: Mesh, faces: np.ndarray) -> np.ndarray:
    """(k,) object: the ``f`` line of each face ``faces`` (k,) int64 of ``fixed``, line end included.

    Faces whose corners all have the same indices (the usual case) are formatted a whole size
    at a time with one format string; a face whose corners differ (some without uv or normal)
    has its corners spelled one by one."""
    lines = np.empty(len(faces), dtype=object)
    sizes = fixed.face_sizes[faces]
    tables = [index for index in (fixed.corner_texcoord, fixed.corner_normal)]
    corner_form = "%d" + ("/%d" if tables[0] is not None else "/" if tables[1] is not None else "") + (
        "/%d" if tables[1] is not None else "")
    for size in np.unique(sizes).tolist():  # one pass per face size
        rows = np.flatnonzero(sizes == size)
        corners = corner_slots(fixed.face_sizes, faces[rows]).reshape(-1, size)
        columns = [fixed.corner_vertex[corners]] + [index[corners] for index in tables if index is not None]
        whole = np.ones(len(rows), dtype=bool)
        for column in columns[1:]:
            whole &= (column >= 0).all(axis=1)
        numbers = np.stack(columns, axis=2).reshape(len(rows), -1)[whole] + 1
        line = "f" + (" " + corner_form) * size + "\n"
        lines[rows[whole]] = [line % row for row in map(tuple, numbers.tolist())]
        for row in np.flatnonzero(~whole).tolist():
            words = _corner_words(fixed, corners[row])
            lines[rows[row]] = "f " + " ".join(words.tolist()) + "\n"
    return lines


def patched_obj(source: bytes, mesh: Mesh, refined: Refined, header: str) -> bytes:
    """The fixed OBJ (module docstring) of ``source``, the bytes ``mesh`` was read from.

    ``header`` is written as a comment line before the appended statements.
    """
    fixed = refined.mesh
    starts = line_starts(source)
    keep = np.ones(len(starts) - 1, dtype=np.int8)
    keep[mesh.face_line[refined.replaced] - 1] = 0
    runs = np.flatnonzero(np.diff(np.concatenate([[0], keep, [0]])))
    kept = b"".join(source[starts[a] : starts[b]] for a, b in zip(runs[::2].tolist(), runs[1::2].tolist()))
    out = ["" if not kept or kept.endswith(b"\n") else "\n", f"# {header}\n"]
    vertex_rows = fixed.positions if fixed.colors is None else np.hstack([fixed.positions, fixed.colors])
    out.append(_statements("v", vertex_rows[len(mesh.positions):]))
    if fixed.texcoords is not None and mesh.texcoords is not None:
        out.append(_statements("vt", fixed.texcoords[len(mesh.texcoords):]))
    if fixed.normals is not None and mesh.normals is not None:
        out.append(_statements("vn", fixed.normals[len(mesh.normals):]))
    new = np.flatnonzero(refined.added)
    lines = _face_lines(fixed, new)
    if len(new):
        state = state_lines(source, starts, mesh.face_line[refined.source[new]])
        first_of_run = np.flatnonzero(np.concatenate([[True], (state[1:] != state[:-1]).any(axis=1)]))
        for row in first_of_run.tolist():  # one restatement per run of faces sharing their state
            stated = sorted(line for line in state[row].tolist() if line > 0)
            lines[row] = "".join(source[starts[line - 1] : starts[line]].decode("latin-1").rstrip("\r\n") + "\n"
                                 for line in stated) + lines[row]
    out += lines.tolist()
    appended = "".join(out)
    if source[: starts[1]].endswith(b"\r\n"):  # a file with Windows line ends gets them on its new lines too
        appended = appended.replace("\n", "\r\n")
    return kept + appended.encode("latin-1")
