"""The Subdivision Surface modifier of an object, read as the settings of the subdivision profile it draws.

What the artist sees of a mesh with a Subdivision Surface modifier is its subdivided surface, not the cage:
the viewport at the modifier's ``levels``, the render at its ``render_levels``. design.md's profiles name
those levels (``game`` 0, ``blender-viewport`` 1, ``blender-render`` 2, ``film`` the limit); Blender's
UV Smooth and Boundary Smooth are OpenSubdiv's face-varying and boundary interpolation rules
(Blender's ``MOD_subsurf`` passes them to OpenSubdiv as such). :func:`subdivision_modifier` reads the
modifier; the check notes it and offers the profile, until the subdivision-aware lint reads it.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Blender's UV Smooth -> OpenSubdiv face-varying linear interpolation (``--fvar-interpolation``).
FVAR_INTERPOLATION = {
    "NONE": "all",
    "PRESERVE_CORNERS": "cornersOnly",
    "PRESERVE_CORNERS_AND_JUNCTIONS": "cornersPlus1",
    "PRESERVE_CORNERS_JUNCTIONS_AND_CONCAVE": "cornersPlus2",
    "PRESERVE_BOUNDARIES": "boundaries",
    "SMOOTH_ALL": "none",
}
#: Blender's Boundary Smooth -> OpenSubdiv boundary interpolation.
BOUNDARY_INTERPOLATION = {"ALL": "edgeOnly", "PRESERVE_CORNERS": "edgeAndCorner"}
#: The profile drawing a mesh at each level (design.md, "Subdivision").
PROFILE_OF_LEVEL = {0: "game", 1: "blender-viewport", 2: "blender-render"}


@dataclass(frozen=True)
class SubdivisionModifier:
    """A Subdivision Surface modifier as the lint's subdivision settings.

    Attributes
    ----------
    name : the modifier's name
    scheme : ``"catmullClark"`` or ``"bilinear"`` (Blender's Simple)
    levels, render_levels : the viewport's and the render's level
    fvar_interpolation : UV Smooth as OpenSubdiv's face-varying rule (:data:`FVAR_INTERPOLATION`)
    boundary_interpolation : Boundary Smooth as OpenSubdiv's boundary rule
    """

    name: str
    scheme: str
    levels: int
    render_levels: int
    fvar_interpolation: str
    boundary_interpolation: str

    @property
    def profile(self) -> str:
        """The ``--profile`` that draws the viewport's level, else ``--subdivision level:N``."""
        return _profile(self.levels)

    @property
    def render_profile(self) -> str:
        return _profile(self.render_levels)

    def note(self, evaluated: bool) -> str:
        """What the panel says: the modifier, and what the findings are of."""
        seen = (f"the viewport's level {self.levels}, With modifiers on" if evaluated else
                f"the cage: Blender draws {self.profile} in the viewport, {self.render_profile} in renders")
        return (f"Subdivision Surface {self.name!r} ({self.scheme}, viewport level {self.levels}, render level "
                f"{self.render_levels}, fvar {self.fvar_interpolation}, boundary {self.boundary_interpolation}): "
                f"findings are of {seen}")


def _profile(level: int) -> str:
    return f"--profile {PROFILE_OF_LEVEL[level]}" if level in PROFILE_OF_LEVEL else f"--subdivision level:{level}"


def subdivision_modifier(obj) -> SubdivisionModifier | None:
    """The first Subdivision Surface modifier of ``obj`` shown in the viewport or the render, or None."""
    for modifier in obj.modifiers:
        if modifier.type == "SUBSURF" and (modifier.show_viewport or modifier.show_render):
            return SubdivisionModifier(
                name=modifier.name,
                scheme="bilinear" if modifier.subdivision_type == "SIMPLE" else "catmullClark",
                levels=int(modifier.levels) if modifier.show_viewport else 0,
                render_levels=int(modifier.render_levels) if modifier.show_render else 0,
                fvar_interpolation=FVAR_INTERPOLATION.get(modifier.uv_smooth, modifier.uv_smooth),
                boundary_interpolation=BOUNDARY_INTERPOLATION.get(modifier.boundary_smooth,
                                                                  modifier.boundary_smooth),
            )
    return None
