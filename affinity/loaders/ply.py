"""Stanford PLY reader: ASCII, binary little- and big-endian.

The header is read line by line; the body element by element. Every element
is read by walking its properties once for *all* its rows together: a
``cursor`` array holds each row's position (a byte offset in binary files, a
number index in ASCII ones) and advances property by property, list counts
included. Binary rows containing lists have data-dependent sizes; their start
offsets are found in runs of rows of equal size (see :func:`_row_starts`).

Used: vertex ``x y z``, ``nx ny nz``, ``red green blue`` (integer types scaled
to [0, 1]), texture coordinates (``s t``, ``u v``, ``texture_u texture_v``,
``texture_s texture_t``); face ``vertex_indices``/``vertex_index`` and per-face
``texcoord`` lists (two numbers per corner). Everything else is skipped. A file
with vertices and neither faces nor triangle strips is a point cloud, not a mesh:
it is skipped (``no-mesh``, :class:`~affinity.errors.SkippedFile`), as a USD
stage without a mesh is; OBJ and OFF files without faces get Q205 instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MeshError, SkippedFile
from ..mesh import Mesh
from .faces import check_indices, polygon_mesh, ragged_positions, unit_colors, whole_indices
from .numbers import out_of_range, out_of_range_reason
from .regular import open_regular
from .text import read_rows

_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip
_FORMATS = {"ascii": None, "binary_little_endian": "<", "binary_big_endian": ">"}
_UV_NAMES = (("s", "t"), ("u", "v"), ("texture_u", "texture_v"), ("texture_s", "texture_t"))
_MAX_HEADER_LINES = 10000


@dataclass
class _Property:
    name: str
    dtype: np.dtype  # item type
    count_dtype: np.dtype | None = None  # list length type; None for a scalar


@dataclass
class _Element:
    name: str
    count: int
    properties: list
    line: int  # header line, for messages


#: The key of the ASCII rows past the declared elements (their line numbers) among an ASCII file's columns.
TRAILING = ":trailing lines"


def load_ply(path) -> Mesh:
    """Read a PLY file (ASCII or binary)."""
    with open_regular(path) as fh:
        order, elements, header_lines = _header(fh, path)
        if order is None:
            columns = _read_ascii(path, fh, elements, header_lines)
        else:
            columns = _read_binary(path, fh.read(), elements, order)
    return _mesh(path, elements, columns)


def _header(fh, path):
    """Parse the header; return (byte order or None for ASCII, elements, header line count)."""
    order, elements = "", []
    for line in range(1, _MAX_HEADER_LINES + 1):
        raw = fh.readline()
        if not raw:
            raise MeshError(path, line, "truncated header: no 'end_header'")
        try:
            words = raw.decode("ascii").split()
        except UnicodeDecodeError:
            raise MeshError(path, line, "header is not ASCII text") from None
        if line == 1:
            if words != ["ply"]:
                raise MeshError(path, 1, "not a PLY file (first line must be 'ply')")
            continue
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "end_header":
            if order == "":
                raise MeshError(path, line, "header has no 'format' line")
            return order, elements, line
        _header_statement(path, line, words, elements)
        if words[0] == "format":
            if len(words) != 3 or words[1] not in _FORMATS:
                raise MeshError(path, line, f"unknown format {' '.join(words[1:])!r}")
            order = _FORMATS[words[1]]
    raise MeshError(path, _MAX_HEADER_LINES, "no 'end_header' in the first 10000 lines")


def _header_statement(path, line, words, elements) -> None:
    """Handle an ``element`` or ``property`` line (other keywords: MeshError)."""
    if words[0] == "element":
        if len(words) != 3 or not words[2].isdigit():
            raise MeshError(path, line, f"bad element line {' '.join(words)!r}")
        elements.append(_Element(words[1], int(words[2]), [], line))
    elif words[0] == "property":
        if not elements:
            raise MeshError(path, line, "property before any element")
        if len(words) == 5 and words[1] == "list" and _TYPES.get(words[2], "f")[0] in "iu" and words[3] in _TYPES:
            prop = _Property(words[4], np.dtype(_TYPES[words[3]]), np.dtype(_TYPES[words[2]]))
        elif len(words) == 3 and words[1] in _TYPES:
            prop = _Property(words[2], np.dtype(_TYPES[words[1]]))
        else:
            raise MeshError(path, line, f"bad property line {' '.join(words)!r}")
        elements[-1].properties.append(prop)
    elif words[0] != "format":
        raise MeshError(path, line, f"unknown header keyword {words[0]!r}")


def _walk(element: _Element, cursor, read, width, limit):
    """Read every property of an element for all rows at once.

    cursor : (R,) int64 position of every row; ``read(positions, dtype)``
    returns (n,) values at positions; ``width(dtype)`` is how far one value
    advances the cursor; ``limit`` (R,) int64 is where each row must end at the
    latest. Returns ``{name: values}`` (scalars: (R,) array; lists: (counts
    (R,) int64, items (sum counts,) array)), the rows' end positions, and the
    first row that overruns its limit (None when all fit).
    """
    columns = {}
    for prop in element.properties:
        if prop.count_dtype is None:
            if (cursor + width(prop.dtype) > limit).any():
                return columns, cursor, int(np.argmax(cursor + width(prop.dtype) > limit))
            columns[prop.name] = read(cursor, prop.dtype)
            cursor = cursor + width(prop.dtype)
            continue
        inside = (cursor + width(prop.count_dtype) <= limit).all()
        counts = read(cursor, prop.count_dtype) if inside else np.full(len(cursor), -1)
        cursor = cursor + width(prop.count_dtype)
        bad = (counts < 0) | (counts != np.round(counts)) | (cursor + counts * width(prop.dtype) > limit)
        if bad.any():
            return columns, cursor, int(np.argmax(bad))
        counts = counts.astype(np.int64)
        columns[prop.name] = (counts, read(ragged_positions(cursor, counts, width(prop.dtype)), prop.dtype))
        cursor = cursor + counts * width(prop.dtype)
    return columns, cursor, None


def _read_ascii(path, fh, elements, header_lines):
    rows = read_rows(fh, path, header_lines + 1)
    needed = sum(e.count for e in elements)
    if len(rows.number) < needed:
        last = int(rows.number[-1]) if len(rows.number) else header_lines
        raise MeshError(path, last, f"truncated: {len(rows.number)} data lines for {needed} element rows")
    # Rows past the declared elements (trimesh's points_emptyascii.ply has one more vertex line than its header
    # says) are left unread, as trimesh and other readers leave them, and named in a note.
    columns, done = {TRAILING: rows.number[needed:]}, 0
    for element in elements:
        span = slice(done, done + element.count)
        first, limit = rows.first[span], rows.first[done + 1 : done + element.count + 1]
        found, end, bad = _walk(element, first, lambda at, dtype: _as_declared(rows.values[at], dtype), lambda _: 1,
                                limit)
        wrong = [bad] if bad is not None else np.flatnonzero(end != limit)
        if len(wrong):
            raise MeshError(path, int(rows.number[span][wrong[0]]),
                            f"{element.name} line does not match the header's properties")
        columns[element.name] = found
        columns[element.name + ":lines"] = rows.number[span]
        done += element.count
    return columns


def _as_declared(values, dtype):
    """ASCII numbers rounded to their declared float type, as a binary file would hold them."""
    if dtype.kind != "f":
        return values
    with np.errstate(over="ignore"):  # too large for the type: inf, reported as not finite
        return values.astype(dtype).astype(np.float64)


def _read_binary(path, data: bytes, elements, order):
    raw = np.frombuffer(data, dtype=np.uint8)

    def read(at, dtype):
        """Values of ``dtype`` (file byte order) at byte offsets ``at``, native order."""
        dtype = dtype.newbyteorder(order)
        view = np.ndarray((max(len(raw) - dtype.itemsize + 1, 0),), dtype=dtype, buffer=raw, strides=(1,))
        return view[at].astype(dtype.newbyteorder("="))

    def width(dtype):
        return dtype.itemsize

    _check_declared_sizes(path, elements, len(data))
    columns, offset = {}, 0
    for element in elements:
        starts = _row_starts(path, element, offset, read, data, order)
        found, end, bad = _walk(element, starts, read, width, np.full(len(starts), len(raw)))
        if bad is not None:
            raise MeshError(path, 0, f"truncated binary data in {element.name} {bad}")
        columns[element.name] = found
        offset = int(end[-1]) if len(end) else offset
    if data[offset:].strip():
        raise MeshError(path, 0, f"{len(data) - offset} bytes after the last element")
    return columns


def _check_declared_sizes(path, elements, size: int) -> None:
    """MeshError (line 0, binary data) for the first element whose rows cannot fit in the
    ``size`` bytes after the header, before anything is allocated for them: every row
    takes at least its scalars and its list counts (an element without properties
    counts one byte a row, so that a header cannot ask for billions of empty rows)."""
    needed = 0
    for element in elements:
        row = sum((p.dtype if p.count_dtype is None else p.count_dtype).itemsize for p in element.properties)
        needed += element.count * max(row, 1)
        if needed > size:
            raise MeshError(path, 0, f"truncated: the header declares {element.count} {element.name} rows (line "
                                     f"{element.line}), at least {needed} bytes, but {size} bytes of data follow it")


def _row_starts(path, element: _Element, offset: int, read, data: bytes, order: str) -> np.ndarray:
    """(R,) int64 byte offset of every row of a binary element.

    Rows without lists have one size. Otherwise rows are taken in runs: guess
    that the next ``window`` rows have the size of the current one, check the
    guess for all of them at once (row sizes follow from their list counts),
    keep the rows up to the first that differs, and grow the window while
    guesses hold: a uniform element (all quads) costs a handful of passes.
    Where runs are short (face sizes alternating), rows are stepped through
    one by one for a while, which costs about a microsecond a row.
    """
    if all(p.count_dtype is None for p in element.properties):
        return offset + sum(p.dtype.itemsize for p in element.properties) * np.arange(element.count, dtype=np.int64)
    starts, done, window = [np.zeros(0, np.int64)], 0, 1024
    while done < element.count:
        row_size = int(_row_ends(element, np.array([offset]), read, len(data))[0]) - offset
        if offset + row_size > len(data):
            raise MeshError(path, 0, f"truncated binary data in {element.name} {done}")
        run = offset + row_size * np.arange(min(window, element.count - done, (len(data) - offset) // row_size))
        same = _row_ends(element, run, read, len(data)) - run == row_size
        kept = len(run) if same.all() else int(np.argmin(same))  # row 0 is the measured one: kept >= 1
        starts.append(run[:kept])
        done += kept
        offset += kept * row_size
        window = window * 2 if kept == len(run) else 64
        if kept < 16 and done < element.count:
            stepped, offset = _step_rows(path, element, offset, min(4096, element.count - done), data, order)
            starts.append(stepped)
            done += len(stepped)
    return np.concatenate(starts)


def _step_rows(path, element: _Element, offset: int, rows: int, data: bytes, order: str):
    """Start offsets of the next ``rows`` rows found one at a time, and the offset after them."""
    byteorder = "big" if order == ">" else "little"
    starts = np.empty(rows, dtype=np.int64)
    for row in range(rows):
        starts[row] = offset
        for prop in element.properties:
            if prop.count_dtype is None:
                offset += prop.dtype.itemsize
                continue
            size = prop.count_dtype.itemsize
            count = int.from_bytes(data[offset : offset + size], byteorder, signed=prop.count_dtype.kind == "i")
            offset += size + count * prop.dtype.itemsize
            if count < 0 or offset > len(data):
                raise MeshError(path, 0, f"truncated binary data in {element.name} (a list runs past the end)")
    return starts, offset


def _row_ends(element: _Element, starts, read, size: int) -> np.ndarray:
    """(R,) int64 end offset of binary rows starting at ``starts`` (``size + 1`` where one cannot be read)."""
    end = starts.copy()
    broken = np.zeros(len(starts), dtype=bool)
    for prop in element.properties:
        if prop.count_dtype is None:
            end += prop.dtype.itemsize
            continue
        inside = np.minimum(end, size - prop.count_dtype.itemsize)
        counts = read(np.maximum(inside, 0), prop.count_dtype).astype(np.int64)
        broken |= (inside != end) | (counts < 0)
        end += prop.count_dtype.itemsize + np.maximum(counts, 0) * prop.dtype.itemsize
    end[broken] = size + 1
    return end


def _mesh(path, elements, columns) -> Mesh:
    names = [e.name for e in elements]
    if "vertex" not in names:
        raise MeshError(path, 0, "no 'vertex' element")
    vertex, lines = columns["vertex"], columns.get("vertex:lines", 0)
    missing = [axis for axis in "xyz" if axis not in vertex]
    if missing:
        raise MeshError(path, elements[names.index("vertex")].line, f"vertex element lacks {', '.join(missing)}")
    positions = np.stack([vertex[a] for a in "xyz"], axis=1).astype(np.float64)
    _require_finite(path, positions, lines)
    face = columns.get("face", {})
    indices = face.get("vertex_indices", face.get("vertex_index"))
    n_faces = elements[names.index("face")].count if "face" in names else 0
    if indices is None and n_faces:
        raise MeshError(path, elements[names.index("face")].line, "face element has no vertex_indices list")
    sizes, corner_vertex = indices if indices is not None else (np.zeros(0, np.int64), np.zeros(0))
    face_line = columns.get("face:lines", np.zeros(len(sizes), np.int64))
    trailing = columns.get(TRAILING, ())
    notes = [] if not len(trailing) else [
        f"{len(trailing)} data line{'s' * (len(trailing) != 1)} after the elements the header declares "
        f"(from line {int(trailing[0])}) not read"]
    strips = columns.get("tristrips", {})
    strips = strips.get("vertex_indices", strips.get("vertex_index"))
    if strips is not None and len(sizes) == 0:
        counts, items = strips
        strip_lines = columns.get("tristrips:lines", np.zeros(len(counts), np.int64))
        items = whole_indices(items, invalid=-2)  # -1 restarts a strip
        check_indices(path, items, len(positions), np.concatenate(([0], np.cumsum(counts))), strip_lines,
                      "vertex", absent=-1)  # every item, also those only in the joins strip_triangles drops
        sizes, corner_vertex, face_line, dropped = strip_triangles(counts, items, strip_lines)
        notes.append(f"{len(sizes)} triangles read from {len(strips[0])} triangle strip list"
                     f"{'s' * (len(strips[0]) != 1)}"
                     + (f" ({dropped} degenerate joining triangles left out)" if dropped else ""))
    if len(sizes) == 0 and len(positions):
        raise SkippedFile(path, "no-mesh")  # a point cloud: vertices, no faces, no strips
    texcoords = corner_texcoord = normals = colors = None
    if all(k in vertex for k in ("nx", "ny", "nz")):
        normals = np.stack([vertex[k] for k in ("nx", "ny", "nz")], axis=1).astype(np.float64)
        _require_finite(path, normals, lines)
    if all(k in vertex for k in ("red", "green", "blue")):
        rgb = [vertex[k] for k in ("red", "green", "blue")]
        prop = next(p for p in elements[names.index("vertex")].properties if p.name == "red")
        scale = float(np.iinfo(prop.dtype).max) if prop.dtype.kind in "iu" else 1.0
        colors = unit_colors(path, np.stack(rgb, axis=1).astype(np.float64), scale, lines, notes)
    if "texcoord" in face:
        counts, uv = face["texcoord"]
        if (counts != 2 * sizes).any():
            raise MeshError(path, int(face_line[np.argmax(counts != 2 * sizes)]),
                            "texcoord list is not two numbers per corner")
        texcoords, corner_texcoord = uv.reshape(-1, 2).astype(np.float64), np.arange(len(corner_vertex))
        _require_finite(path, texcoords, 0 if np.isscalar(lines) else np.repeat(face_line, sizes))
    else:
        uv_names = next((pair for pair in _UV_NAMES if all(k in vertex for k in pair)), None)
        if uv_names:
            texcoords = np.stack([vertex[k] for k in uv_names], axis=1).astype(np.float64)
            _require_finite(path, texcoords, lines)
    mesh = polygon_mesh(path, positions, sizes, corner_vertex, face_line, texcoords, corner_texcoord, normals, colors)
    mesh.notes += notes
    return mesh


def strip_triangles(counts, items, row_lines):
    """Triangles of PLY ``tristrips`` lists, in OpenGL strip order.

    counts : (R,) int64 items per list; items : (sum counts,) vertex indices,
    -1 ending one strip and starting the next (a list's end does too);
    row_lines : (R,) int64 source line of every list. Triangle ``k`` of a strip
    is ``(v[k], v[k+1], v[k+2])``, odd ``k`` swapping the first two so every
    triangle keeps the strip's orientation. Triangles with a repeated vertex
    (the zero-area joins strippers insert) are left out.

    Returns ``sizes (T,) int64`` (all 3), ``corners (3T,) int64``, ``face_line
    (T,) int64`` and the number of triangles left out.

    >>> sizes, corners, lines, dropped = strip_triangles(np.array([6]), np.array([0, 1, 2, 3, -1, 4]), np.array([9]))
    >>> corners.reshape(-1, 3).tolist(), dropped
    ([[0, 1, 2], [2, 1, 3]], 0)
    """
    blob = np.asarray(items).astype(np.int64)
    row = np.repeat(np.arange(len(counts)), counts)
    new_strip = np.ones(len(blob), dtype=bool)
    new_strip[1:] = (blob[1:] == -1) | (row[1:] != row[:-1])
    strip = np.cumsum(new_strip) - 1
    begin = np.flatnonzero(new_strip)
    offset = np.arange(len(blob)) - begin[strip] - (blob[begin] == -1)[strip]
    a, b, c = blob[:-2], blob[1:-1], blob[2:]
    whole = (strip[:-2] == strip[2:]) & (a != -1) & (b != -1) & (c != -1)
    odd = (offset[:-2] % 2 == 1)
    triangles = np.stack([np.where(odd, b, a), np.where(odd, a, b), c], axis=1)
    degenerate = (a == b) | (b == c) | (a == c)
    keep = whole & ~degenerate
    return (np.full(int(keep.sum()), 3, dtype=np.int64), triangles[keep].reshape(-1),
            np.asarray(row_lines, dtype=np.int64)[row[:-2][keep]], int((whole & degenerate).sum()))

def _require_finite(path, values, lines) -> None:
    """MeshError at the line of the first row of ``values`` (n, k) with a NaN, an inf or a value
    beyond :data:`~.numbers.LARGEST`."""
    bad = out_of_range(values).any(axis=1)
    if bad.any():
        row = int(np.argmax(bad))
        line = lines if np.isscalar(lines) else int(lines[row])
        if np.isfinite(values[row]).all():
            raise MeshError(path, line, out_of_range_reason(values[row][out_of_range(values[row])][0]))
        raise MeshError(path, line, f"value {values[row]} is not finite")
