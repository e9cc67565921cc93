"""The project's exceptions, in one module that imports nothing, so any layer may raise or catch them.

- :class:`UsageError`: bad command-line or configuration input (exit 2).
- :class:`MeshError`: a file that cannot be read as a mesh (Q901, with its line).
- :class:`SkippedFile`: a file deliberately not checked (an LFS pointer, a stage with no mesh).
"""

from __future__ import annotations


class UsageError(Exception):
    """Bad command-line input that is not about one mesh file (exit 2)."""


class MeshError(Exception):
    """A file that cannot be read as a mesh.

    ``line`` is the 1-based source line the problem was found on, 0 when the
    problem has no line (binary data, a missing file).
    """

    def __init__(self, path: str, line: int, reason: str):
        super().__init__(f"{path}:{line}: {reason}")
        self.path = str(path)
        self.line = int(line)
        self.reason = reason


class SkippedFile(Exception):
    """A file that is deliberately not checked (e.g. a Git LFS pointer); not an error."""

    def __init__(self, path: str, reason: str):
        super().__init__(f"{path}: skipped ({reason})")
        self.path = str(path)
        self.reason = reason


def internal_error(err: BaseException) -> str:
    """An unexpected exception while checking or fixing one file, as the one line said for that file (at most
    300 characters): ``internal error: ValueError: ...``."""
    return " ".join(f"internal error: {type(err).__name__}: {err}".split())[:300]
