"""File names as a terminal shows them: control characters escaped, never sent.

A file name may hold any byte but ``/`` and NUL: a newline would split a finding's
line in two, an ESC sequence would recolour or rewrite the terminal, a bidi
override would reorder what is read. :func:`printable` is applied wherever a
human-facing line names a file (text findings, the lines on stderr, ``--show-files``,
``--show-settings``). Machine formats (JSON, SARIF, JUnit, GitHub annotations)
keep the name exact and escape it by their own rules.
"""

from __future__ import annotations

_SHORT_ESCAPES = {"\a": "\\a", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\v": "\\v", "\f": "\\f", "\r": "\\r",
                  '"': '\\"', "\\": "\\\\"}


def printable(name: str) -> str:
    """``name`` as it is when every character prints (``str.isprintable``, a space included), else
    quoted as git quotes paths: ``"a\\nb"``, with C escapes, ``\\"`` and ``\\\\``, ``\\xNN`` for the other
    ASCII controls and for a byte that is not UTF-8 (kept by Python as a surrogate escape), ``\\uXXXX``
    for other characters that do not print (C1 controls, format characters such as bidi overrides,
    separators).

    >>> printable("meshes/chair.obj")
    'meshes/chair.obj'
    >>> print(printable("a\\nb\\x1b[31m.obj"))
    "a\\nb\\x1b[31m.obj"
    >>> print(printable("caf\\udce9.obj"))
    "caf\\xe9.obj"
    """
    if name.isprintable():
        return name
    return '"' + "".join(_escaped(c) for c in name) + '"'


def _escaped(c: str) -> str:
    if c in _SHORT_ESCAPES:
        return _SHORT_ESCAPES[c]
    if c.isprintable():
        return c
    point = ord(c)
    if point < 0x80:
        return f"\\x{point:02x}"
    if 0xDC80 <= point <= 0xDCFF:  # os.fsdecode's stand-in for the undecodable byte point - 0xDC00
        return f"\\x{point - 0xDC00:02x}"
    return f"\\u{point:04x}" if point <= 0xFFFF else f"\\U{point:08x}"
