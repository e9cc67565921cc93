"""Q201-Q204: the shape of the quad itself, whatever it carries."""

from __future__ import annotations

import numpy as np

from ..geometry import degeneracy, fold_degrees, folded_fraction, interior_angles, is_bowtie, zero_area
from .families import QUAD_SHAPE
from .registry import Measured, rule

REFERENCES = ("Bloomenthal 2022, §3.4 (nonplanar and degenerate quads); "
              "Hormann & Tarini 2004, §4 (concave and self-crossing quads).")
#: The attributes of the scored rules a quad without area or a bow-tie takes over (one finding per defect).
EVERY_ATTRIBUTE = ("texcoords", "colors", "normals")


def no_area(quads) -> np.ndarray:
    """(Q,) bool: the quads whose whole area is at or below Q201's threshold (a pole quad, one repeated corner,
    is a triangle with area: not these)."""
    return zero_area(quads.planar, quads.settings.threshold("Q201"))


def self_crossing(quads) -> np.ndarray:
    """(Q,) bool: the bow-ties (Q204's test)."""
    return is_bowtie(quads.planar)


@rule(code="Q201", name="degenerate-quad", unit="relative area", default_threshold=1e-9, flags="at-or-below",
      worst="lowest", family=QUAD_SHAPE, masks=EVERY_ATTRIBUTE, unmeasurable=no_area, cause="it has no area",
      fix_leaves="degenerate", fix_precedence=0, fix_uncut=True, references=REFERENCES)
def degenerate(quads) -> Measured:
    """Zero area, collapsed edge or repeated corner.

    What it does:
        Flags quads with a repeated corner, a collapsed edge or an area at or below
        the threshold relative to their size. A quad whose whole area is at or below
        the threshold gets no Q101-Q103, whether or not this rule is selected (one
        finding per defect; the message says so); a quad with one repeated corner
        (a pole quad) is a triangle with area and keeps them: their value is exact
        there. The value reported is the area of the smallest of the four triangles
        of the two splits relative to the squared longest edge: 0 where two corners
        coincide, as in the example.

    Why it matters:
        One of the two triangles of the split covers no pixels, so the half of the
        attribute it carries is lost, and any test or interpolation that divides by
        its area is undefined (the pole rows of a lat-long sphere).

    Example:
        # a quad with a repeated corner
        v 0 0 0
        v 1 0 0
        v 1 1 0
        f 1 2 3 3

    Prints:
        example.obj:5:1: Q201 warning degenerate-quad: zero area, collapsed edge or repeated corner (0 vs 1e-09 relative area) [face 0]

    Use instead:
        # the collapsed corners merged: the triangle the face really is
        v 0 0 0
        v 1 0 0
        v 1 1 0
        f 1 2 3

    How to fix:
        Merge the collapsed corners (Blender: Mesh > Clean Up > Merge by Distance)
        so the face becomes the triangle it really is; a face with no area at all
        is dissolved (Blender: Mesh > Clean Up > Degenerate Dissolve), and its
        neighbours' attributes are then measured as usual.
    """
    return Measured(slice(None), degeneracy(quads.planar))


@rule(code="Q202", name="nonplanar-quad", unit="degrees", default_threshold=45.0, folding=True,
      family=QUAD_SHAPE, fix_leaves="nonplanar", fix_precedence=2, references=REFERENCES)
def nonplanar(quads) -> Measured:
    """The split folds: the two triangles meet at an angle along the diagonal.

    What it does:
        Measures the fold angle between the two triangles of the split along the
        diagonal (the diagonal setting; with diagonal = both, the worse of the two
        splits), in degrees, and flags quads above the threshold. 45 degrees is
        where Blender's 3D-Print Toolbox calls a face distorted. A triangle without
        area folds nothing here: that quad is Q201's. The affinity test runs on the
        projection onto the quad's plane. In the example the split along the
        diagonal 0-2 has triangle normals (0, -1, 1) and (-1, 0, 1): it folds by
        arccos(1/2), the 60 degrees printed below (the split along 1-3 folds by
        arccos(1/sqrt 3), 54.74 degrees, and diagonal = both reports the worse).

    Why it matters:
        A folded quad has no single flat shape: each diagonal split gives a
        different surface and lighting, and no interpolation is exact. Slight folds
        are the nature of base meshes built for subdivision; a sharp one shows as a
        crease wherever the engine picks the other diagonal.

    Example:
        # the unit square with one corner lifted by 1
        v 0 0 0
        v 1 0 0
        v 1 1 1
        v 0 1 0
        f 1 2 3 4

    Prints:
        example.obj:6:1: Q202 warning nonplanar-quad: the split folds: the two triangles meet at an angle along the diagonal (60 vs 45 degrees) [face 0]

    Use instead:
        # the same corners triangulated along the intended diagonal: each triangle is flat
        v 0 0 0
        v 1 0 0
        v 1 1 1
        v 0 1 0
        f 1 2 3
        f 1 3 4

    How to fix:
        Flatten the quad (Blender: Mesh > Clean Up > Make Planar Faces), subdivide
        it, or triangulate it along the intended diagonal.
    """
    return Measured(slice(None), fold_degrees(quads.planar, quads.settings.diagonal))


def at_most_straight(quads) -> np.ndarray:
    """(Q,) float64 bound of Q203's value: 180 degrees where no corner turns clockwise (every interior angle
    is 180 - atan2(turn, dot) with turn >= 0, turns within the tolerance read as 0), +inf elsewhere."""
    return np.where(quads.planar.reflex.any(axis=1), np.inf, 180.0)


@rule(code="Q203", name="concave-quad", level="info", unit="degrees", default_threshold=180.0,
      family=QUAD_SHAPE, fix_uncut=True, references=REFERENCES, bound=at_most_straight)
def concave(quads) -> Measured:
    """One corner is reflex.

    What it does:
        Flags quads whose largest interior angle, in their own plane, is above the
        threshold (180 degrees: a reflex corner). The example's edges leave its
        reflex corner at atan(1/3) to the axes, so its interior angle is
        270 - 2 atan(1/3) degrees, the 233.1 printed below.

    Why it matters:
        Splitting along the wrong diagonal folds a triangle outside the quad;
        bilinear inversion is ambiguous. Concave quads are often modelled on
        purpose (darts along a silhouette) and every engine splits them through the
        reflex corner, so the rule is info by default.

    Example:
        # a dart: the corner at (0.5, 0.5) points inward
        v 0 0 0
        v 2 0 0
        v 0.5 0.5 0
        v 0 2 0
        f 1 2 3 4

    Prints:
        example.obj:6:1: Q203 info concave-quad: one corner is reflex (233.1 vs 180 degrees) [face 0]

    Use instead:
        # the same dart with its reflex corner moved outward: a convex kite
        v 0 0 0
        v 2 0 0
        v 1.5 1.5 0
        v 0 2 0
        f 1 2 3 4

    How to fix:
        Move the reflex corner outward, or split the quad into two triangles along
        the diagonal through the reflex corner (Blender: Face > Triangulate).
    """
    rows = np.flatnonzero(~is_bowtie(quads.planar))
    return Measured(rows, interior_angles(quads.planar).max(axis=1)[rows])


@rule(code="Q204", name="bowtie-quad", level="error", unit="folded fraction", family=QUAD_SHAPE,
      masks=EVERY_ATTRIBUTE, unmeasurable=self_crossing, cause="it has no consistent orientation",
      fix_leaves="bowtie", fix_precedence=1, fix_uncut=True, references=REFERENCES)
def bowtie(quads) -> Measured:
    """The quad crosses itself.

    What it does:
        Flags quads whose edges cross (a bow-tie) in their own plane; the value
        reported is the folded fraction of the quad: the share of its corner-turn
        area (the sum of |T_i|, T_i the doubled area of the triangle at corner i)
        that turns clockwise, 1/2 for a symmetric bow-tie such as the example's. A
        bow-tie gets no Q101-Q103, whether or not this rule is selected (one
        finding per defect).

    Why it matters:
        A self-crossing quad has no consistent orientation; one half renders
        back-facing.

    Example:
        # the unit square with its corners in the order (0,0), (1,1), (1,0), (0,1)
        v 0 0 0
        v 1 1 0
        v 1 0 0
        v 0 1 0
        f 1 2 3 4

    Prints:
        example.obj:6:1: Q204 error bowtie-quad: the quad crosses itself (0.5 folded fraction) [face 0]

    Use instead:
        # the same corners in the order (0,0), (1,0), (1,1), (0,1): the crossing edges flipped
        v 0 0 0
        v 1 1 0
        v 1 0 0
        v 0 1 0
        f 1 3 2 4

    How to fix:
        Reorder the corners (flip the crossing edge) or delete and refill the face
        (Blender: select the four vertices, F).
    """
    rows = np.flatnonzero(is_bowtie(quads.planar))
    return Measured(rows, folded_fraction(quads.planar.take(rows)))
