"""Small quads and findings built by hand: corner lists, OBJ text of separate quads, RuleHits, a sample CheckRun."""

from __future__ import annotations

import numpy as np

from affinity.findings import FileReport, RuleHits
from affinity.output import CheckRun
from affinity.settings import Settings

SQUARE = [(0, 0), (1, 0), (1, 1), (0, 1)]


UNIT_UV = [(0, 0), (1, 0), (1, 1), (0, 1)]


def trapezoid(top: float = 1.0, x: float = 0.0) -> list[tuple[float, float]]:
    """Bottom 2 wide, top ``top`` wide, height 1, shifted by ``x``."""
    return [(x - 1, 0), (x + 1, 0), (x + top / 2, 1), (x - top / 2, 1)]


def quad_obj(quads, groups: list[str] | None = None, header: str = "") -> str:
    """OBJ text of separate quads, each ``(corners xy, uv)``; optionally a ``g`` line before each face."""
    vertices, faces = [header] if header else [], []
    for i, (corners, uv) in enumerate(quads):
        vertices += [f"v {x} {y} 0" for x, y in corners] + [f"vt {u} {v}" for u, v in uv]
        if groups:
            faces.append(f"g {groups[i]}")
        faces.append("f " + " ".join(f"{4 * i + k}/{4 * i + k}" for k in range(1, 5)))
    return "\n".join(vertices + faces) + "\n"


def hits(code: str, faces, lines, values, threshold: float = 0.5, groups=None) -> RuleHits:
    n = len(faces)
    return RuleHits(code, np.array(faces), np.array(lines), np.array(values, dtype=float), threshold,
                    np.zeros(n, dtype=np.int32) if groups is None else np.array(groups, dtype=np.int32))


def sample_run() -> CheckRun:
    """A flagged file (two Q101, one Q204 error), a clean file, an unreadable and a skipped one."""
    counts = {"faces": 3, "quads": 3, "triangles": 0, "ngons": 0}
    return CheckRun(
        [
            FileReport("a, b:c.obj", counts=counts, group_names=["body"],
                       hits=[hits("Q101", [2, 0], [12, 10], [256.0, 3.5]), hits("Q204", [1], [11], [0.3], 0.0)]),
            FileReport("clean.obj", counts=counts, group_names=[""]),
            FileReport("broken.obj", error="face index 9 out of range\r\n(1 based)", error_line=4),
            FileReport("big.obj", skipped="lfs-pointer"),
        ],
        Settings(),
    )


def trapezoids(widths) -> str:
    """Separate trapezoids (bottom 2 wide, top ``w`` wide) with unit-square uv: Q101 grows as ``w`` shrinks."""
    vertices = "".join(f"v {3 * i} 0 0\nv {3 * i + 2} 0 0\nv {3 * i + 1 + w / 2} 1 0\nv {3 * i + 1 - w / 2} 1 0\n"
                       for i, w in enumerate(widths))
    faces = "".join(f"f {4 * i + 1}/1 {4 * i + 2}/2 {4 * i + 3}/3 {4 * i + 4}/4\n" for i in range(len(widths)))
    return vertices + "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n" + faces
