"""Q201-Q204: the shape of the quad itself, whatever it carries."""

from __future__ import annotations

import numpy as np

from ..geometry import degeneracy, folded_fraction, interior_angles, is_bowtie
from .registry import Rule, register

REFERENCES = "Bloomenthal 2022, §3.4 (nonplanar and degenerate quads); Hormann & Tarini 2004, §4 (concave and self-crossing quads)."


def degenerate(quads) -> tuple:
    """Q201: the quad's area relative to its size."""
    return slice(None), degeneracy(quads.planar)


def nonplanar(quads) -> tuple:
    """Q202: the distance between the diagonals relative to their mean length."""
    return slice(None), quads.planar.warp


def concave(quads) -> tuple:
    """Q203: the largest interior angle, in degrees, of the quads that are not bow-ties."""
    planar = quads.planar
    candidates = ~is_bowtie(planar)
    if quads.settings.threshold("Q203") >= 180:
        # An angle above 180 degrees needs a clockwise turn; half the tolerance
        # keeps every turn interior_angles could read as one.
        candidates &= (planar.areas < -0.5 * planar.tolerance[:, None]).any(axis=1)
    rows = np.flatnonzero(candidates)
    if len(rows) == 0:
        return rows, np.zeros(0)
    return rows, interior_angles(planar.take(rows)).max(axis=1)


def bowtie(quads) -> tuple:
    """Q204: the folded fraction of the self-crossing quads."""
    rows = np.flatnonzero(is_bowtie(quads.planar))
    return rows, folded_fraction(quads.planar.take(rows))


register(Rule(
    code="Q201", name="degenerate-quad",
    summary="zero area, collapsed edge or repeated corner",
    unit="relative area", default_threshold=1e-9, flags="at-or-below", worst="lowest",
    check=degenerate,
    what=(
        "Flags quads with a repeated corner, a collapsed edge or an area at or "
        "below the threshold relative to their size."
    ),
    why=(
        "One of the two triangles of the split covers no pixels, so the half of the "
        "attribute it carries is lost, and any test or interpolation that divides "
        "by its area is undefined (the pole rows of a lat-long sphere)."
    ),
    example="# a quad with a repeated corner\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3 3\n",
    example_output=(
        'example.obj:5:1: Q201 degenerate-quad: zero area, collapsed edge or repeated corner'
        ' (0 vs 1e-09 relative area)\n'
    ),
    fix=(
        "Merge the collapsed corners (Blender: Mesh > Clean Up > Merge by "
        "Distance) so the face becomes the triangle it really is."
    ),
    references=REFERENCES,
))

register(Rule(
    code="Q202", name="nonplanar-quad",
    summary="corners do not lie in one plane (warp above tolerance)",
    unit="relative warp", default_threshold=0.01,
    check=nonplanar,
    what=(
        "Measures the distance between the two diagonals relative to their mean "
        "length and flags quads above the threshold; the affinity test runs on the "
        "projection onto the quad's plane."
    ),
    why=(
        "A warped quad has no single flat shape: each diagonal split gives a "
        "different surface and lighting, and no interpolation is exact."
    ),
    example="# the unit square with one corner lifted by 0.2\nv 0 0 0\nv 1 0 0\nv 1 1 0.2\nv 0 1 0\nf 1 2 3 4\n",
    example_output=(
        'example.obj:6:1: Q202 nonplanar-quad: corners do not lie in one plane'
        ' (warp above tolerance) (0.06967 vs 0.01 relative warp)\n'
    ),
    fix=(
        "Flatten the quad (Blender: Mesh > Clean Up > Make Planar Faces) or "
        "triangulate it along the intended diagonal."
    ),
    references=REFERENCES,
))

register(Rule(
    code="Q203", name="concave-quad",
    summary="one corner is reflex",
    unit="degrees", default_threshold=180.0,
    check=concave,
    what=(
        "Flags quads whose largest interior angle, in their own plane, is above "
        "the threshold (180 degrees: a reflex corner)."
    ),
    why=(
        "Splitting along the wrong diagonal folds a triangle outside the quad; "
        "bilinear inversion is ambiguous."
    ),
    example="# a dart: the corner at (0.5, 0.5) points inward\nv 0 0 0\nv 2 0 0\nv 0.5 0.5 0\nv 0 2 0\nf 1 2 3 4\n",
    example_output='example.obj:6:1: Q203 concave-quad: one corner is reflex (233.1 vs 180 degrees)\n',
    fix=(
        "Move the reflex corner outward, or split the quad into two triangles along "
        "the diagonal through the reflex corner (Blender: Face > Triangulate)."
    ),
    references=REFERENCES,
))

register(Rule(
    code="Q204", name="bowtie-quad",
    summary="the quad crosses itself", level="error",
    check=bowtie,
    what=(
        "Flags quads whose edges cross (a bow-tie) in their own plane; the value "
        "reported is the folded fraction of the quad."
    ),
    why=(
        "A self-crossing quad has no consistent orientation; one half renders "
        "back-facing."
    ),
    example="# the unit square with its corners in the order (0,0), (1,1), (1,0), (0,1)\nv 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n",
    example_output='example.obj:6:1: Q204 bowtie-quad: the quad crosses itself (0.5)\n',
    fix=(
        "Reorder the corners (flip the crossing edge) or delete and refill the "
        "face (Blender: select the four vertices, F)."
    ),
    references=REFERENCES,
))
