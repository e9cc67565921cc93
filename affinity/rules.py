"""The rule table: one source for the CLI, ``affinity rule``, SARIF and the README.

Codes never change; names are kebab-case. Every rule's documentation follows the
ruff layout (what it does, why it matters, an example, the fix) and ends with a
fix a modelling tool can apply.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Rule:
    code: str
    name: str
    summary: str
    unit: str
    default_threshold: float | None
    what: str
    why: str
    example: str
    fix: str
    level: str = "warning"


_CREASE = (
    "A GPU draws every quad as two triangles and interpolates each triangle "
    "linearly. When the attribute is not an affine image of the positions, the two "
    "triangles disagree about its gradient and a crease appears along the diagonal: "
    "a kink in the texture, a colour seam, a bend in the shading. Which diagonal the "
    "engine or baker picks changes the picture."
)

RULES: dict[str, Rule] = {
    rule.code: rule
    for rule in [
        Rule(
            "Q101", "uv-disaffine",
            "texture coordinates are not an affine image of the positions",
            "texels", 0.5,
            "Measures, per quad, how far the two-triangle split moves the texture "
            "coordinate at the quad's centre, in texels (texture size from the "
            "material's map_Kd image, else the texture-size setting).",
            _CREASE,
            "A trapezoid (a quad near the pole of a lat-long sphere) mapped to a "
            "rectangle in UV: the split shifts the texture by several texels at the "
            "centre and the checker lines bend along the diagonal.",
            "Re-UV the quad as a parallelogram matching its shape (e.g. follow active "
            "quads / straighten), subdivide it, or render it with generalized "
            "barycentric coordinates (affinity render --method hybrid).",
        ),
        Rule(
            "Q102", "color-disaffine",
            "vertex colours are not an affine image of the positions",
            "1/255", 2.0,
            "Measures how far the split moves the vertex colour at the quad's centre, "
            "in 1/255 steps.",
            _CREASE,
            "A square with corner colours blue, red, green, black: the colours do not "
            "form a parallelogram in colour space, so the two triangles blend "
            "differently and a diagonal seam shows.",
            "Paint the corner colours so opposite corners average to the same colour, "
            "subdivide the quad, or triangulate before baking so the choice is explicit.",
        ),
        Rule(
            "Q103", "normal-disaffine",
            "normals are not an affine image of the positions",
            "degrees", 2.0,
            "Measures how far the split turns the interpolated normal at the quad's "
            "centre, in degrees.",
            _CREASE,
            "A quad on a cylinder with smooth normals but uneven corner spacing: the "
            "lighting shows a bend along the diagonal.",
            "Subdivide the quad, even out its corners, or triangulate before baking "
            "normals so the split diagonal is fixed.",
        ),
        Rule(
            "Q201", "degenerate-quad",
            "zero area, collapsed edge or repeated corner",
            "relative area", 1e-9,
            "Flags quads with a repeated corner, a collapsed edge or an area that is "
            "zero relative to their size.",
            "One of the two triangles of the split covers no pixels, so the half of the "
            "attribute it carries is lost (the pole rows of a lat-long sphere).",
            "A quad on a sphere's pole with two corners at the pole.",
            "Merge the collapsed corners and make the face a triangle.",
        ),
        Rule(
            "Q202", "nonplanar-quad",
            "corners do not lie in one plane (warp above tolerance)",
            "relative warp", 0.01,
            "Measures the distance between the two diagonals relative to their mean "
            "length; the affinity test runs on the projection onto the quad's plane.",
            "A warped quad has no single flat shape: each diagonal split gives a "
            "different surface and lighting, and no interpolation is exact.",
            "A quad with one corner lifted off the plane of the other three.",
            "Flatten the quad (planarize) or triangulate it along the intended diagonal.",
        ),
        Rule(
            "Q203", "concave-quad",
            "one corner is reflex",
            "degrees", 180.0,
            "Flags quads with an interior angle above 180 degrees in their own plane.",
            "Splitting along the wrong diagonal folds a triangle outside the quad; "
            "bilinear inversion is ambiguous.",
            "A dart-shaped quad.",
            "Move the reflex corner outward or split the quad into two triangles along "
            "the diagonal through the reflex corner.",
        ),
        Rule(
            "Q204", "bowtie-quad",
            "the quad crosses itself",
            "", None,
            "Flags quads whose edges cross (a bow-tie) in their own plane.",
            "A self-crossing quad has no consistent orientation; one half renders "
            "back-facing.",
            "Corners given in the order 0, 2, 1, 3.",
            "Reorder the corners (flip the crossing edge) or rebuild the face.",
            level="error",
        ),
        Rule(
            "Q205", "no-faces",
            "the mesh has vertices but no faces",
            "", None,
            "Flags a readable file that has vertices but no faces.",
            "Nothing will render; usually a broken export (point cloud, lost face block).",
            "An OBJ with only v lines.",
            "Re-export the mesh with faces.",
        ),
        Rule(
            "Q301", "uv-degenerate",
            "zero area in texture space",
            "relative area", 1e-9,
            "Flags quads whose texture-space area is zero relative to their UV size.",
            "The whole quad samples a line or a point of the texture: it smears.",
            "All four corners share one UV.",
            "Unwrap the face again so it gets its own area in UV space.",
        ),
        Rule(
            "Q302", "uv-flipped",
            "texture orientation reversed against the surface",
            "", None,
            "Flags quads whose UV winding is clockwise while the face winding is "
            "counter-clockwise (a mirrored UV island).",
            "Mirrored UVs flip the tangent frame: normal maps light the wrong way.",
            "A UV island mirrored to save texture space.",
            "Flip the island in the UV editor, or split tangents at the mirror seam.",
        ),
    ]
}

UNREADABLE = Rule(
    "Q901", "unreadable", "file cannot be parsed", "", None,
    "Reports a file that cannot be read as a mesh, with the line.",
    "Nothing in it can be checked.",
    "A truncated OBJ, a face index out of range, NaN coordinates.",
    "Re-export the file from the modelling tool.",
    level="error",
)


def resolve_codes(select: list[str] | None, ignore: list[str] | None) -> list[str]:
    """Rule codes enabled by ``select``/``ignore`` prefixes (``"Q1"``, ``"Q101"``, ``"ALL"``)."""

    def matches(code: str, prefixes: list[str]) -> bool:
        return any(p == "ALL" or code.startswith(p.upper()) for p in prefixes)

    codes = [c for c in RULES if select is None or matches(c, select)]
    return [c for c in codes if not (ignore and matches(c, ignore))]
