"""Q301-Q302: the quad in texture space."""

from __future__ import annotations

import numpy as np

from ..geometry import relative_signed_area
from .families import UV_LAYOUT
from .registry import Measured, rule

#: The uv quad without area: routing by view reads its threshold (a degenerate uv quad routes by the lint's error).
UV_DEGENERATE = "Q301"


def collapsed_uv(quads) -> np.ndarray:
    """(Q,) bool: the quads whose uv collapses to a line or a point (Q301's test at its threshold)."""
    from .registry import RULES

    collapsed = np.zeros(len(quads), dtype=bool)
    if quads.tables.tables.get("texcoords") is not None:
        area = uv_degenerate(quads)
        collapsed[area.rows] = RULES[UV_DEGENERATE].flagged(area.values, quads.settings.threshold(UV_DEGENERATE))
    return collapsed


@rule(code=UV_DEGENERATE, name="uv-degenerate", unit="relative area", default_threshold=1e-9, flags="at-or-below",
      worst="lowest", attribute="texcoords", family=UV_LAYOUT, masks=("texcoords",), unmeasurable=collapsed_uv,
      cause="the texture smears over it", fix_leaves="uv-degenerate", fix_precedence=3, fix_uncut=True)
def uv_degenerate(quads) -> Measured:
    """Zero area in texture space.

    What it does:
        Flags quads whose texture-space area is at or below the threshold relative
        to their UV size (its signed uv area over its squared longest uv edge,
        0 where the corners share one line, as in the example). Such a quad gets
        no Q101 (its uv has no affine map to measure), whether or not this rule
        is selected: one finding per defect, and the message says so.

    Why it matters:
        The whole quad samples a line or a point of the texture: it smears.

    Example:
        # a square whose four corners share one line of uv
        v 0 0 0
        v 1 0 0
        v 1 1 0
        v 0 1 0
        vt 0 0
        vt 1 0
        f 1/1 2/2 3/2 4/1

    Prints:
        example.obj:8:1: Q301 warning uv-degenerate: zero area in texture space: the texture smears over it, so Q101 is not measured on it (0 vs 1e-09 relative area) [face 0]

    Use instead:
        # the square unwrapped again into an island of its own, the texture's upper right quarter
        v 0 0 0
        v 1 0 0
        v 1 1 0
        v 0 1 0
        vt 0.5 0.5
        vt 1 0.5
        vt 1 1
        vt 0.5 1
        f 1/1 2/2 3/3 4/4

    References:
        Bloomenthal 2022, §2 (the barycentric test divides by the uv triangles' areas).

    How to fix:
        Unwrap the face again so it gets its own area in UV space (Blender: select
        it, UV > Unwrap); the texture no longer smears over it, and Q101 then
        measures its affinity.
    """
    return Measured(quads.uv[0], np.abs(relative_signed_area(quads.uv_planar)))


@rule(code="Q302", name="uv-flipped", level="info", unit="relative area", worst="lowest", attribute="texcoords",
      mirroring=True, family=UV_LAYOUT)
def uv_flipped(quads) -> Measured:
    """Texture orientation reversed against the surface.

    What it does:
        Flags quads whose UV winding is clockwise while the face winding is
        counter-clockwise (a mirrored UV island); the value reported is the negative
        relative UV area (the signed uv area over the squared longest uv edge: -1
        for the example's mirrored square). Quads whose UV area is within
        Q301's threshold (as configured) are Q301's: degenerate, not flipped.

    Why it matters:
        Mirrored UVs flip the tangent frame: normal maps light the wrong way.
        Mirroring is also a common way to save texture space and is invisible
        without a normal map, so the rule is info by default (set its level to
        warning in [levels] when the asset bakes normal maps).

    Example:
        # a UV island mirrored to save texture space
        v 0 0 0
        v 1 0 0
        v 1 1 0
        v 0 1 0
        vt 1 0
        vt 0.5 0
        vt 0.5 0.5
        vt 1 0.5
        f 1/1 2/2 3/3 4/4

    Prints:
        example.obj:10:1: Q302 info uv-flipped: texture orientation reversed against the surface (-1 relative area) [face 0]

    Use instead:
        # the island mirrored back in place: uv turns the way the face does
        v 0 0 0
        v 1 0 0
        v 1 1 0
        v 0 1 0
        vt 0.5 0
        vt 1 0
        vt 1 0.5
        vt 0.5 0.5
        f 1/1 2/2 3/3 4/4

    References:
        Mikkelsen 2008, Simulation of wrinkled surfaces revisited (tangent frames at mirrored UVs).

    How to fix:
        Flip the island in the UV editor (Blender: UV > Mirror), or split tangents at
        the mirror seam.
    """
    rows = np.arange(len(quads))[quads.uv[0]]
    area = relative_signed_area(quads.uv_planar)
    flipped = area < -quads.settings.threshold("Q301")
    return Measured(rows[flipped], area[flipped])
