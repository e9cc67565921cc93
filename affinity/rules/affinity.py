"""Q101-Q103: is the attribute an affine image of the positions? (Bloomenthal 2022, §2 and Listing 3)."""

from __future__ import annotations

import numpy as np

from ..measures import barycentric_score, color_steps, normal_degrees, texels
from .families import COLOR_AFFINITY, NORMAL_AFFINITY, UV_AFFINITY
from .registry import Measured, rule

#: The paper's own tolerance for its dimensionless barycentric reading.
BARYCENTRIC_TOLERANCE = 0.01

CREASE = (
    "A GPU draws every quad as two triangles and interpolates each triangle "
    "linearly. When the attribute is not an affine image of the positions, the two "
    "triangles disagree about its gradient and a crease appears along the diagonal: "
    "picture a checker texture on the quad whose lines run straight across one "
    "triangle, kink where they meet the diagonal and run straight again at another "
    "angle across the other triangle. The same kink shows as a colour seam or a bend "
    "in the shading. Which diagonal the engine or baker picks changes the picture, "
    "so the asset looks different in every tool."
)
REFERENCES = (
    "Bloomenthal 2022, Barycentric quad rasterization (JCGT 11(3)), §2 and Listing 3 (the affinity test); "
    "Hormann & Tarini 2004, A quadrilateral rendering primitive (mean value coordinates, the fix a renderer applies)."
)

#: The uv rule: a bare ``--threshold N`` (and ``threshold = N`` in a configuration file) sets its threshold.
UV_DISAFFINE = "Q101"


@rule(code=UV_DISAFFINE, name="uv-disaffine", unit="texels", default_threshold=0.5, visible_threshold=2.0, attribute="texcoords", scored=True,
      visible_reading=True, family=UV_AFFINITY, readings={"barycentric": ("barycentric score", BARYCENTRIC_TOLERANCE)}, why=CREASE, references=REFERENCES)
def uv_disaffinity(quads) -> Measured:
    """Texture coordinates are not an affine image of the positions.

    What it does:
        Measures, per quad, the largest difference between the two-triangle split
        and the quad's own bilinear interpolation of its texture coordinates, in
        texels (texture size from the header of the texture the face's material
        binds, else the texture-size setting; the first finding of a file says when
        the size was assumed), and flags quads above the threshold: a warning up to
        2 texels, an error above, where the crease is plainly visible. Where the
        quad's textures decode, the finding reads the crease through them instead:
        C, the largest colour difference the split makes on screen, in 1/255 (degrees
        for normal maps), levelled by visible-error, visible-warning and
        visible-min-shift, the shift kept beside it (docs/measure.md, "The visible
        reading"). With --measure
        centre it takes the split's shift at the quad's centre instead, with
        --measure barycentric the paper's dimensionless score at .01. On the
        example's trapezoid (side ratio r = 1/2) the split shifts the texture at
        its centre by an eighth of its width, 128 texels at 1024 (--measure
        centre), and at its worst by (1 - r) / (1 + sqrt r)^2 of the width, the
        175.7 texels printed below. A quad whose uv is an affine image of its
        positions (a parallelogram carrying a parallelogram, or the trapezoid below
        re-UVed in its own shape) is never flagged.

    Example:
        # a trapezoid (a quad near the pole of a lat-long sphere) carrying the unit square of uv
        v -1 0 0
        v 1 0 0
        v 0.5 1 0
        v -0.5 1 0
        vt 0 0
        vt 1 0
        vt 1 1
        vt 0 1
        f 1/1 2/2 3/3 4/4

    Prints:
        example.obj:10:1: Q101 error uv-disaffine: texture coordinates are not an affine image of the positions: no texture found, texels of an assumed 1024x1024 texture (give the size with --texture-size or the texture-size setting) (175.7 vs 0.5 texels) [face 0]

    Use instead:
        # the same trapezoid re-UVed in its own shape, uv = ((x + 2) / 4, (y + 1) / 4): an affine map
        v -1 0 0
        v 1 0 0
        v 0.5 1 0
        v -0.5 1 0
        vt 0.25 0.25
        vt 0.75 0.25
        vt 0.625 0.5
        vt 0.375 0.5
        f 1/1 2/2 3/3 4/4

    How to fix:
        Refine the quad: affinity fix splits it into n x n quads on its own
        bilinear surface, carrying the bilinear uv, until each piece's crease is
        under the threshold (up to n^2 - 1 more faces, the neighbours re-cut so
        nothing cracks); subdividing does the same. Where that needs more than
        --max-refine, re-UV it as a parallelogram matching its shape (Blender: UV >
        Follow Active Quads, or straighten the island); the texture then has to be
        re-baked. Triangulating does not remove the crease: it only makes every
        tool draw the same one, along the diagonal you chose.
    """
    rows, uv = quads.uv
    diagonal = quads.settings.diagonal
    if quads.settings.measure == "barycentric":
        return Measured(rows, barycentric_score(quads.planar.take(rows), quads.uv_planar, diagonal))
    return Measured(rows, texels(quads.split_error(rows, uv).T, quads.texel_size(rows)))


@rule(code="Q102", name="color-disaffine", unit="1/255", default_threshold=2.0, visible_threshold=8.0, attribute="colors", scored=True,
      family=COLOR_AFFINITY, why=CREASE, references=REFERENCES)
def color_disaffinity(quads) -> Measured:
    """Vertex colours are not an affine image of the positions.

    What it does:
        Measures the largest difference between the split's and the quad's bilinear
        vertex colour, in 1/255 steps, and flags quads above the threshold: a
        warning up to 8/255, an error above, where the seam is plainly visible.
        On a parallelogram the two differ most at its centre, by a quarter of
        |c0 - c1 + c2 - c3| (c0 to c3 the corner colours in [0, 1]): on the
        example, |(-1, 1, 1)| / 4 = sqrt(3) / 4, the 255 sqrt(3) / 4 = 110.4 steps
        printed below. Colours with c0 + c2 = c1 + c3 are an affine image of the
        parallelogram and are never flagged.

    Example:
        # a unit square with corner colours blue, red, green, black: no parallelogram in colour space
        v 0 0 0 0 0 1
        v 1 0 0 1 0 0
        v 1 1 0 0 1 0
        v 0 1 0 0 0 0
        f 1 2 3 4

    Prints:
        example.obj:6:1: Q102 error color-disaffine: vertex colours are not an affine image of the positions (110.4 vs 2/255) [face 0]

    Use instead:
        # the same square repainted blue, red, yellow, cyan: the colours vary evenly, c0 + c2 = c1 + c3
        v 0 0 0 0 0 1
        v 1 0 0 1 0 0
        v 1 1 0 1 1 0
        v 0 1 0 0 1 1
        f 1 2 3 4

    How to fix:
        Refine the quad (affinity fix, or subdivide it) so each piece carries a
        smaller change of colour, or repaint its corner colours so they vary
        evenly across it: the two diagonals then average to the same colour
        (c0 + c2 = c1 + c3). Triangulating does not remove the seam: it only
        makes every tool draw the same one.
    """
    rows, colors = quads.complete("colors")
    return Measured(rows, color_steps(quads.split_error(rows, colors).T))


@rule(code="Q103", name="normal-disaffine", unit="degrees", default_threshold=2.0, visible_threshold=8.0, attribute="normals", scored=True,
      family=NORMAL_AFFINITY, why=CREASE, references=REFERENCES)
def normal_disaffinity(quads) -> Measured:
    """Normals are not an affine image of the positions.

    What it does:
        Measures how far the split turns the interpolated normal at its worst point,
        atan2(|split - bilinear|, |mean corner normal|) in degrees, and flags quads
        above the threshold: a warning up to 8 degrees, an error above, where the
        bend in the shading is plainly visible. On a parallelogram with unit corner
        normals n0 to n3 the split turns the normal most at the centre, by
        atan2(|n0 - n1 + n2 - n3|, |n0 + n1 + n2 + n3|): on the example that is
        atan((19 - 8 sqrt 5) / sqrt 41), the 9.847 degrees printed below. Normals
        with n0 + n2 = n1 + n3 (a cylinder's, turning along one direction) are
        never flagged.

    Example:
        # a flat square whose corner normals lean out unevenly: the lighting bends along the diagonal
        v 0 0 0
        v 1 0 0
        v 1 1 0
        v 0 1 0
        vn 0 0 1
        vn 0.5 0 1
        vn 0 0 1
        vn 0 0.5 1
        f 1//1 2//2 3//3 4//4

    Prints:
        example.obj:10:1: Q103 error normal-disaffine: normals are not an affine image of the positions (9.847 vs 2 degrees) [face 0]

    Use instead:
        # the same square with a cylinder's normals: they turn evenly along x, n0 + n2 = n1 + n3
        v 0 0 0
        v 1 0 0
        v 1 1 0
        v 0 1 0
        vn -0.6 0 0.8
        vn 0.6 0 0.8
        f 1//1 2//2 3//2 4//1

    How to fix:
        Refine the quad (affinity fix, or subdivide it) so each piece spans a
        smaller turn of the normals, or smooth its corner normals so they turn
        evenly across it (Blender: Mesh > Normals > Smooth Vectors, or relax the
        loop). Triangulating before baking normals does not remove the bend: it
        only makes every tool shade the same one.
    """
    rows, unit = quads.complete("normals")  # unit length already (see affinity.lint.CornerTables.gather)
    return Measured(rows, normal_degrees(quads.split_error(rows, unit).T, np.transpose(unit, (2, 1, 0))))
