"""Q301-Q302: the quad in texture space."""

from __future__ import annotations

import numpy as np

from ..geometry import relative_signed_area
from .registry import RULES, Rule, register


def uv_degenerate(quads) -> tuple:
    """Q301: the quad's uv area relative to its uv size."""
    return quads.uv[0], np.abs(relative_signed_area(quads.uv_planar))


def uv_flipped(quads) -> tuple:
    """Q302: the negative relative uv area of the quads whose uv winds against the face."""
    rows = np.arange(len(quads))[quads.uv[0]]
    area = relative_signed_area(quads.uv_planar)
    flipped = area < -RULES["Q301"].default_threshold
    return rows[flipped], area[flipped]


register(Rule(
    code="Q301", name="uv-degenerate",
    summary="zero area in texture space",
    unit="relative area", default_threshold=1e-9, flags="at-or-below", worst="lowest", attribute="texcoords",
    check=uv_degenerate,
    what=(
        "Flags quads whose texture-space area is at or below the threshold "
        "relative to their UV size."
    ),
    why="The whole quad samples a line or a point of the texture: it smears.",
    example=(
        "# a square whose four corners share one line of uv\n"
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nf 1/1 2/2 3/2 4/1\n"
    ),
    example_output='example.obj:8:1: Q301 uv-degenerate: zero area in texture space (0 vs 1e-09 relative area) [face 0]\n',
    fix="Unwrap the face again so it gets its own area in UV space.",
    references="Bloomenthal 2022, §2 (the barycentric test divides by the uv triangles' areas).",
))

register(Rule(
    code="Q302", name="uv-flipped",
    summary="texture orientation reversed against the surface", level="info",
    unit="relative area", worst="lowest", attribute="texcoords",
    check=uv_flipped,
    what=(
        "Flags quads whose UV winding is clockwise while the face winding is "
        "counter-clockwise (a mirrored UV island); the value reported is the "
        "negative relative UV area."
    ),
    why=(
        "Mirrored UVs flip the tangent frame: normal maps light the wrong way. "
        "Mirroring is also a common way to save texture space and is invisible "
        "without a normal map, so the rule is info by default (set its level to "
        "warning in [levels] when the asset bakes normal maps)."
    ),
    example=(
        "# a UV island mirrored to save texture space\n"
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 1 0\nvt 0 0\nvt 0 1\nvt 1 1\nf 1/1 2/2 3/3 4/4\n"
    ),
    example_output='example.obj:10:1: Q302 uv-flipped: texture orientation reversed against the surface (-1 relative area) [face 0]\n',
    fix=(
        "Flip the island in the UV editor (Blender: UV > Mirror), or split "
        "tangents at the mirror seam."
    ),
    references="Mikkelsen 2008, Simulation of wrinkled surfaces revisited (tangent frames at mirrored UVs).",
))
