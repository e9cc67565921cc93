"""The validator families: which rules each UsdValidation validator and NVIDIA rule runs.

One validator per rule family, named after it; the three affinity families carry a
fixer (``affinity fix``'s refinement). Error names are the rule names
(``uv-disaffine``), so a fixer is tied to its rule's errors.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Family:
    """``name`` (the validator's, after the module prefix), the rule ``codes`` it runs, whether its
    findings can be fixed by refinement, and its one-line ``doc``."""

    name: str
    codes: tuple[str, ...]
    fixable: bool
    doc: str


FAMILIES = (
    Family("UvAffinity", ("Q101",), True,
           "quad-affinity Q101: texture coordinates that are not an affine image of the quad (a crease along the "
           "split diagonal), in texels."),
    Family("ColorAffinity", ("Q102",), True,
           "quad-affinity Q102: vertex colours that are not an affine image of the quad, in 1/255 steps."),
    Family("NormalAffinity", ("Q103",), True,
           "quad-affinity Q103: normals that are not an affine image of the quad, in degrees."),
    Family("QuadShape", ("Q201", "Q202", "Q203", "Q204", "Q205"), False,
           "quad-affinity Q201-Q205: degenerate, nonplanar, concave and bow-tie quads, meshes without faces."),
    Family("UvLayout", ("Q301", "Q302"), False,
           "quad-affinity Q301-Q302: quads with no area in texture space, or mirrored against the surface."),
)
