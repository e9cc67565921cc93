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
    "picture a checker texture on the quad whose lines run straight across one "
    "triangle, kink where they meet the diagonal and run straight again at another "
    "angle across the other triangle. The same kink shows as a colour seam or a bend "
    "in the shading. Which diagonal the engine or baker picks changes the picture, "
    "so the asset looks different in every tool."
)

RULES: dict[str, Rule] = {
    rule.code: rule
    for rule in [
        Rule(
            "Q101", "uv-disaffine",
            "texture coordinates are not an affine image of the positions",
            "texels", 0.5,
            "Measures, per quad, the largest difference between the two-triangle split "
            "and the quad's own bilinear interpolation of its texture coordinates, in "
            "texels (texture size from the material's map_Kd image, else the "
            "texture-size setting), and flags quads above the threshold. With "
            "--measure centre it takes the split's shift at the quad's centre instead, "
            "with --measure barycentric the paper's dimensionless score at .01.",
            _CREASE,
            "A trapezoid, 2 wide at the bottom and 1 wide at the top (a quad near the "
            "pole of a lat-long sphere), carrying the whole unit square of uv: "
            "corners (-1, 0), (1, 0), (0.5, 1), (-0.5, 1) with uv (0, 0), (1, 0), "
            "(1, 1), (0, 1). The split shifts the texture at its centre by an eighth "
            "of its width, 128 texels at 1024, and by 176 texels at its worst, "
            "(1 - r) / (1 + sqrt r)^2 of the width for the side ratio r = 1/2; the "
            "checker lines bend along the diagonal. A parallelogram whose uv is a "
            "parallelogram (an affine map) is never flagged.",
            "Re-UV the quad as a parallelogram matching its shape (Blender: UV > "
            "Follow Active Quads, or straighten the island), subdivide it so each "
            "piece is closer to a parallelogram, or triangulate before baking so every "
            "tool uses the same diagonal.",
        ),
        Rule(
            "Q102", "color-disaffine",
            "vertex colours are not an affine image of the positions",
            "1/255", 2.0,
            "Measures the largest difference between the split's and the quad's bilinear "
            "vertex colour, in 1/255 steps, and flags quads above the threshold.",
            _CREASE,
            "A unit square with corner colours blue, red, green, black: the colours do "
            "not form a parallelogram in colour space, so the two triangles blend "
            "differently and a diagonal seam shows. Blue, red, yellow, cyan do form "
            "one and are clean.",
            "Repaint the corner colours so opposite corners average to the same "
            "colour, subdivide the quad, or triangulate before baking so the "
            "diagonal is explicit.",
        ),
        Rule(
            "Q103", "normal-disaffine",
            "normals are not an affine image of the positions",
            "degrees", 2.0,
            "Measures how far the split turns the interpolated normal at its worst "
            "point, atan2(|split - bilinear|, |mean corner normal|) in degrees, and "
            "flags quads above the threshold.",
            _CREASE,
            "A quad on a cylinder with smooth normals but uneven corner spacing: the "
            "lighting shows a bend along the diagonal.",
            "Subdivide the quad or even out its corners (Blender: Mesh > Clean Up, or "
            "relax the loop), or triangulate before baking normals so the split "
            "diagonal is fixed.",
        ),
        Rule(
            "Q201", "degenerate-quad",
            "zero area, collapsed edge or repeated corner",
            "relative area", 1e-9,
            "Flags quads with a repeated corner, a collapsed edge or an area at or "
            "below the threshold relative to their size.",
            "One of the two triangles of the split covers no pixels, so the half of the "
            "attribute it carries is lost, and any test or interpolation that divides "
            "by its area is undefined (the pole rows of a lat-long sphere).",
            "A quad on a sphere's pole with two corners at the pole.",
            "Merge the collapsed corners (Blender: Mesh > Clean Up > Merge by "
            "Distance) so the face becomes the triangle it really is.",
        ),
        Rule(
            "Q202", "nonplanar-quad",
            "corners do not lie in one plane (warp above tolerance)",
            "relative warp", 0.01,
            "Measures the distance between the two diagonals relative to their mean "
            "length and flags quads above the threshold; the affinity test runs on the "
            "projection onto the quad's plane.",
            "A warped quad has no single flat shape: each diagonal split gives a "
            "different surface and lighting, and no interpolation is exact.",
            "The unit square with one corner lifted off the plane of the other three "
            "by 0.2: its diagonals pass about 0.07 of their length apart.",
            "Flatten the quad (Blender: Mesh > Clean Up > Make Planar Faces) or "
            "triangulate it along the intended diagonal.",
        ),
        Rule(
            "Q203", "concave-quad",
            "one corner is reflex",
            "degrees", 180.0,
            "Flags quads whose largest interior angle, in their own plane, is above "
            "the threshold (180 degrees: a reflex corner).",
            "Splitting along the wrong diagonal folds a triangle outside the quad; "
            "bilinear inversion is ambiguous.",
            "A dart: corners (0, 0), (2, 0), (0.5, 0.5), (0, 2); the corner at "
            "(0.5, 0.5) points inward with an interior angle of about 233 degrees.",
            "Move the reflex corner outward, or split the quad into two triangles along "
            "the diagonal through the reflex corner (Blender: Face > Triangulate).",
        ),
        Rule(
            "Q204", "bowtie-quad",
            "the quad crosses itself",
            "", None,
            "Flags quads whose edges cross (a bow-tie) in their own plane; the value "
            "reported is the folded fraction of the quad.",
            "A self-crossing quad has no consistent orientation; one half renders "
            "back-facing.",
            "The unit square with its corners listed in the order (0, 0), (1, 1), "
            "(1, 0), (0, 1): two edges cross at the centre.",
            "Reorder the corners (flip the crossing edge) or delete and refill the "
            "face (Blender: select the four vertices, F).",
            level="error",
        ),
        Rule(
            "Q205", "no-faces",
            "the mesh has vertices but no faces",
            "", None,
            "Flags a readable file that has vertices but no faces; the value reported "
            "is the number of vertices.",
            "Nothing will render; usually a broken export (point cloud, lost face block).",
            "An OBJ with only v lines (a point cloud or an export that lost its faces).",
            "Re-export the mesh with faces enabled in the exporter's geometry options.",
        ),
        Rule(
            "Q301", "uv-degenerate",
            "zero area in texture space",
            "relative area", 1e-9,
            "Flags quads whose texture-space area is at or below the threshold "
            "relative to their UV size.",
            "The whole quad samples a line or a point of the texture: it smears.",
            "A quad whose four corners share one UV, or whose UVs lie on one line.",
            "Unwrap the face again so it gets its own area in UV space.",
        ),
        Rule(
            "Q302", "uv-flipped",
            "texture orientation reversed against the surface",
            "", None,
            "Flags quads whose UV winding is clockwise while the face winding is "
            "counter-clockwise (a mirrored UV island); the value reported is the "
            "negative relative UV area.",
            "Mirrored UVs flip the tangent frame: normal maps light the wrong way.",
            "A UV island mirrored to save texture space.",
            "Flip the island in the UV editor (Blender: UV > Mirror), or split "
            "tangents at the mirror seam.",
        ),
    ]
}

UNREADABLE = Rule(
    "Q901", "unreadable", "file cannot be parsed", "", None,
    "Reports a file that cannot be read as a mesh, with the line. It is not a lint "
    "finding: the message goes to stderr, the exit code is 2, and --select/--ignore "
    "do not apply to it.",
    "Nothing in it can be checked.",
    "A truncated OBJ, a face index out of range, NaN coordinates.",
    "Re-export the file from the modelling tool.",
    level="error",
)

#: The documentation sections of every rule, in order: (heading, Rule attribute).
SECTIONS = (
    ("What it does", "what"),
    ("Why it matters", "why"),
    ("Example", "example"),
    ("How to fix", "fix"),
)


def find_rule(key: str) -> Rule | None:
    """The rule (Q901 included) with code or name ``key`` (case-insensitive), or None."""
    key = key.strip()
    for rule in (*RULES.values(), UNREADABLE):
        if key.upper() == rule.code or key.lower() == rule.name:
            return rule
    return None


def threshold_text(rule: Rule) -> str:
    """``"0.5 texels"``, or ``""`` for a rule without a threshold."""
    return "" if rule.default_threshold is None else with_unit(f"{rule.default_threshold:g}", rule.unit)


def with_unit(number: str, unit: str) -> str:
    """``"0.5 texels"``; a unit ``1/N`` reads as a fraction (``"2/255"``, not ``"2 1/255"``)."""
    if unit.startswith("1/"):
        return number + unit[1:]
    return f"{number} {unit}".rstrip()


def rule_page(rule: Rule, markdown: bool = False) -> str:
    """The rule's documentation page: title, summary, level and threshold, then :data:`SECTIONS`.

    Plain text for ``affinity rule``, Markdown for SARIF ``help.markdown``.
    """
    import textwrap

    facts = f"Level: {rule.level}."
    if threshold_text(rule):
        facts += f" Default threshold: {threshold_text(rule)} (setting thresholds.{rule.code})."
    if markdown:
        head = [f"## {rule.code} {rule.name}", "", f"*{rule.summary}*", "", facts]
        body = [part for title, attr in SECTIONS for part in ("", f"### {title}", "", getattr(rule, attr))]
    else:
        head = [f"{rule.code} {rule.name}: {rule.summary}", facts]
        body = [
            part
            for title, attr in SECTIONS
            for part in ("", title, textwrap.fill(getattr(rule, attr), 79, initial_indent="    ",
                                                  subsequent_indent="    "))
        ]
    return "\n".join(head + body) + "\n"


def rules_table() -> str:
    """The Markdown rule table of the README (generated, never edited by hand)."""
    rows = [
        "`affinity rules` lists the rules; `affinity rule CODE` prints a rule's page: what it does, "
        "why it matters, an example and how to fix it.",
        "",
        "| Code | Name | Level | Default threshold | Flags | How to fix |",
        "|---|---|---|---|---|---|",
    ]
    for rule in (*RULES.values(), UNREADABLE):
        rows.append(
            f"| {rule.code} | `{rule.name}` | {rule.level} | {threshold_text(rule) or '-'} "
            f"| {rule.summary} | {rule.fix} |"
        )
    return "\n".join(rows) + "\n"


def resolve_codes(select: list[str] | None, ignore: list[str] | None) -> list[str]:
    """Rule codes enabled by ``select``/``ignore`` prefixes (``"Q1"``, ``"Q101"``, ``"ALL"``)."""

    def matches(code: str, prefixes: list[str]) -> bool:
        return any(p == "ALL" or code.startswith(p.upper()) for p in prefixes)

    codes = [c for c in RULES if select is None or matches(c, select)]
    return [c for c in codes if not (ignore and matches(c, ignore))]
