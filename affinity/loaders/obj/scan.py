"""The scan phase of the OBJ reader: what kind each line is, and the rare statements.

The kinds of line (``v``, ``vt``, ``vn``, ``f``; 0 for anything else), the numbers each
element line may carry, the :class:`Part` a chunk contributes to the mesh, the statements
that may run longer than a chunk (:data:`LONG_LINE`, for the chunk reader), and the
statements without bulk (``g``, ``o``, ``usemtl``, ...), read one by one.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ...errors import MeshError
from ..faces import ragged_positions
from ..numbers import PAD
from ..resources import uncommented
from ..text import Tokens

V, VT, VN, F = 1, 2, 3, 4
#: Numbers a line of each kind may carry: ``v x y z [w]``, ``v x y z r g b [a]``,
#: ``vt u [v [w]]``, ``vn x y z``.
WIDTHS = {V: (3, 4, 6, 7), VT: (1, 2, 3), VN: (3,)}
ELEMENT_OF_SLOT = (V, VT, VN)
SLOT_NAMES = ("vertex", "texture coordinate", "normal")
SLASH = ord("/")
_KEYWORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


@dataclass
class Part:
    """What one chunk contributes; indices are still relative to the chunk.

    ``corners[k]`` is (C,) int64 0-based index for slot ``k`` (vertex, texcoord,
    normal), -1 where a corner lacks it, or None when no corner of the chunk
    has the slot; ``relative[k]`` lists the corners whose index counted back
    from the chunk's own elements and still needs the count of elements before
    the chunk added. ``bounds[k]`` is (min, max) of ``corners[k]`` without them.
    ``face_sizes`` is an int when every face of the chunk has that many corners.
    Line numbers count from the chunk's first line (see :meth:`affinity.loaders.obj.assembly.Assembly.result`).
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


#: Every keyword of the OBJ format (Advanced Visualizer manual, Appendix B1), and ``fo``, an
#: old spelling of ``f``: a chunk holding none of them is not OBJ (prose, a CSV, a log).
_OBJ_KEYWORDS = frozenset(
    "v vt vn vp f fo l p cstype deg bmat step curv curv2 surf parm trim hole scrv sp end con g s mg o "
    "bevel c_interp d_interp lod usemtl mtllib shadow_obj trace_obj ctech stech maplib usemap".split()
)
#: Statements that may run longer than a chunk: faces, lines and points of many corners,
#: free-form lists, group names, comments.
LONG_LINE = re.compile(rb"[ \t]*(?:#|(?:fo?|l|p|g|curv2?|surf|parm|trim|hole|scrv|sp|con)[ \t])")


def line_kinds(tokens: Tokens, counts) -> np.ndarray:
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
    kind[one & v] = V
    kind[one & (first == ord("f"))] = F
    if two.any():
        two &= v
        kind[two & (second == ord("t"))] = VT
        kind[two & (second == ord("n"))] = VN
    return kind


def line_tokens(tokens: Tokens, lines):
    """Tokens after the keyword of ``lines``: per-line count (n,) and indices (sum,) int64."""
    width = tokens.counts[lines] - 1
    return width, ragged_positions(tokens.first[lines] + 1, width)


def token_block(tokens: Tokens, lines, width: int, previous: bool = False):
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


def require_statement(tokens: Tokens, path, lines: np.ndarray, offset: int) -> None:
    """MeshError unless one of ``lines`` (a chunk's non-blank lines, none of them v/vt/vn/f)
    opens with an OBJ keyword; looked at until the first that does."""
    for line in lines:
        if tokens.text(tokens.first[line]) in _OBJ_KEYWORDS:
            return
    size = int(tokens.end[lines[-1]] - tokens.begin[lines[0]])
    raise MeshError(path, int(tokens.number[lines[0]]),
                    f"no OBJ statement in the {size:,} bytes at offset {offset + int(tokens.begin[lines[0]]) - PAD:,}:"
                    f" not an OBJ file")


#: Statements without geometry (``o``, ``g``, ``s``, ``usemtl``, ``mtllib``, ``l``, ...) a chunk of
#: :data:`~affinity.loaders.text.CHUNK_BYTES` (2 MiB) may hold beyond four per v/vt/vn/f line of it. Each
#: is read in Python (some 5 us): 4,096 of them cost about what the chunk's 2 MiB of geometry costs,
#: while four per geometry line cover an exporter that writes ``g``, ``usemtl`` and ``s`` before every
#: face. More is text that holds no mesh (64 MB of ``o x`` lines took 40 s before it was found empty).
STATEMENT_BUDGET = 4096
#: Statements without geometry allowed per v/vt/vn/f line of a chunk, beyond :data:`STATEMENT_BUDGET`.
STATEMENTS_PER_GEOMETRY_LINE = 4


def require_geometry(tokens: Tokens, path, statements: np.ndarray, geometry_lines: int) -> None:
    """MeshError at the first of a chunk's ``statements`` (line indices of its statements without geometry)
    past :data:`STATEMENT_BUDGET` plus :data:`STATEMENTS_PER_GEOMETRY_LINE` per geometry line of the chunk."""
    budget = STATEMENT_BUDGET + STATEMENTS_PER_GEOMETRY_LINE * geometry_lines
    if len(statements) > budget:
        raise MeshError(path, int(tokens.number[statements[budget]]),
                        f"{len(statements):,} statements (o, g, s, usemtl, mtllib, ...) beside {geometry_lines:,} "
                        f"v/vt/vn/f lines in a stretch of the file: more than {STATEMENT_BUDGET:,} plus "
                        f"{STATEMENTS_PER_GEOMETRY_LINE} per geometry line, not a mesh")


def read_statement(tokens: Tokens, path, line, faces_before, part: Part) -> None:
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


