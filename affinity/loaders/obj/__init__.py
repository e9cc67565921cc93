"""Wavefront OBJ reader, vectorized over lines and corners, in named phases.

- **scan** (:mod:`.scan`): the file is read in chunks of whole lines (``\\``
  continuations joined); each chunk is tokenized once at whitespace and '/', and its lines
  are classified by their keyword (``v``, ``vt``, ``vn``, ``f``). Statements without bulk
  (``g``, ``o``, ``usemtl``, ``mtllib``, ``s``, ``l``, ...) are rare and read one by one; a
  chunk holding more of them than :data:`~.scan.STATEMENT_BUDGET` plus four per geometry line
  is not a mesh (Q901 at the statement past the budget), before any is read.
- **vertex tables** (:mod:`.vertices`): the numbers of all lines of one kind are parsed in
  one call and reshaped by their per-line counts.
- **faces** (:mod:`.faces`): a face token's role in its corner (``v``, ``vt`` or ``vn``
  slot) follows from the separator before it; one corner validator checks every face and
  one fix-up resolves relative (negative) indices.
- **assembly** (:mod:`.assembly`): the chunks' parts are appended in file order to the
  growing arrays of the mesh, relative indices that reach before their chunk are resolved,
  and every index is range-checked against the whole file (indices may refer to elements
  defined later in the file).

Each phase has one fast path and one general path, chosen by a single test per chunk.
The fast path takes the common exported file: a chunk whose lines are laid out alike is
read as byte columns (:mod:`.alike`, no tokens); otherwise lines of one kind that carry the
same number of tokens are one ``(lines, tokens)`` block, and face lines laid out like the
first one integer matrix whose columns are the corners' slots. The general path reads
token by token. Whenever the fast path meets something it does not take, the chunk goes
to the general path, which names the line of every error: both give the same mesh and
the same error (``load_obj(..., fast=False)`` forces the general path; a test compares them).

Chunks are parsed on worker threads (NumPy releases the GIL inside its loops) while the
main thread reads the file and adds each finished chunk, in file order, to the mesh, so
no chunk's arrays outlive it.
"""

from __future__ import annotations

import os

import numpy as np

from ...errors import MeshError
from ...mesh import Mesh
from ..numbers import PAD
from ..references import obj_resources
from ..regular import read_regular
from ..text import BufferReader, NotText, read_chunks, tokenize
from . import alike
from .assembly import Assembly
from .faces import face_corners
from .scan import LONG_LINE, WIDTHS, F, Part, V, line_kinds, read_statement, require_geometry, require_statement
from .vertices import check_colors, element_rows, reject_slashes

#: Chunks parsed in parallel (NumPy releases the GIL inside its loops).
_WORKERS = 2


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
        assembly = Assembly(len(source))
        chunks = read_chunks(BufferReader(source), path, continuations=True, size=chunk_bytes, count_lines=False,
                             long_line=LONG_LINE)
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


def _parse_chunk(chunk, path, fast: bool) -> Part:
    """The :class:`~.scan.Part` of one chunk: read as byte columns when its lines are laid out
    alike (:mod:`.alike`), else tokenized and read phase by phase (:mod:`.scan`, :mod:`.vertices`,
    :mod:`.faces`)."""
    part = alike.alike_part(chunk) if fast else None
    if part is not None:
        return part
    tokens = tokenize(chunk, path, slash=True)
    counts = tokens.counts
    kind = line_kinds(tokens, counts)
    element_lines = {k: np.flatnonzero(kind == k) for k in WIDTHS}
    nan_colors = []
    elements = {k: element_rows(tokens, path, lines, k, nan_colors, fast) for k, lines in element_lines.items()}
    check_colors(tokens, path, element_lines[V], elements[V])
    elements = {k: rows.T for k, rows in elements.items()}  # by component, as the column reader gives them
    face_lines = np.flatnonzero(kind == F)
    sizes, corners, relative, bounds, face_slashes = face_corners(tokens, path, kind, face_lines, fast)
    if tokens.slashes != face_slashes:
        # Some '/' is not where a face layout puts one; when every one is, none
        # can touch a number of a v/vt/vn line and the lines need no look.
        for lines in element_lines.values():
            reject_slashes(tokens, path, lines)
    part = Part(
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
        require_statement(tokens, path, statements, chunk.offset)
    require_geometry(tokens, path, statements, len(kind) - len(statements))
    if len(statements):
        faces_before = np.cumsum(kind == F)
        for line in statements:
            read_statement(tokens, path, line, int(faces_before[line]), part)
    return part


