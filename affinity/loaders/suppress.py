"""Inline suppressions in OBJ files: ``# affinity: ignore[Q101]`` comments, found in one pass over the bytes.

The OBJ reader drops comments; this pass looks for the directive only. On a
face line it silences that face; on a ``g`` or ``o`` line it silences every
face up to the next ``g``/``o`` line (like ruff's ``noqa``, per group). Codes
are rule codes or prefixes, comma-separated; ``ignore`` without brackets
silences every rule. Files without the word ``affinity:`` cost one one-byte find (its ':').
"""

from __future__ import annotations

import re

import numpy as np

from .text import find_word

_DIRECTIVE = re.compile(rb"#[^\n]*?affinity:[ \t]*ignore(?:\[([A-Za-z0-9_, \t]*)\])?")
_GROUP_LINE = re.compile(rb"^[ \t]*[go](?=[ \t\r\n]|$)", re.MULTILINE)
_MARKER = b"affinity:"


def _line_numbers(newlines: np.ndarray, offsets: list[int]) -> np.ndarray:
    """(k,) int64 1-based line of each byte offset; ``newlines`` the sorted offsets of b"\\n"."""
    return np.searchsorted(newlines, np.asarray(offsets, dtype=np.int64)) + 1


def inline_ignores(data: bytes, face_line: np.ndarray) -> list[tuple[list[str], np.ndarray]]:
    """``(codes, faces)`` pairs: the rule codes (prefixes; ``["ALL"]``) each directive
    silences and the (k,) int64 faces it covers. ``data`` is the OBJ file's bytes, as its
    loader read them (:func:`affinity.loaders.read_source`); ``face_line`` (F,) int64 is the
    1-based source line of every face, ascending (OBJ file order)."""
    if find_word(data, _MARKER, len(_MARKER) - 1) < 0:
        return []
    found = list(_DIRECTIVE.finditer(data))
    if not found:
        return []
    newlines = np.flatnonzero(np.frombuffer(data, dtype=np.uint8) == 10)
    lines = _line_numbers(newlines, [m.start() for m in found])
    groups = None
    pairs = []
    for match, line in zip(found, lines.tolist()):
        start = data.rfind(b"\n", 0, match.start()) + 1
        keyword = data[start:match.start()].split(None, 1)[:1]
        codes = (["ALL"] if match.group(1) is None
                 else [c.strip().upper() for c in match.group(1).decode().split(",") if c.strip()])
        if keyword == [b"f"]:
            at = np.searchsorted(face_line, line)
            faces = np.arange(at, np.searchsorted(face_line, line, side="right"))
        elif keyword in ([b"g"], [b"o"]):
            if groups is None:
                groups = _line_numbers(newlines, [m.start() for m in _GROUP_LINE.finditer(data)])
            following = groups[groups > line]
            end = following[0] if len(following) else np.iinfo(np.int64).max
            faces = np.arange(np.searchsorted(face_line, line, side="right"), np.searchsorted(face_line, end))
        else:
            continue
        if codes and len(faces):
            pairs.append((codes, faces))
    return pairs
