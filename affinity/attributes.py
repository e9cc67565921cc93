"""The attribute registry: one :class:`Attribute` record per per-corner mesh attribute.

What a quad can carry besides its positions (texture coordinates, vertex
colours, normals) is described here once: the :class:`~affinity.mesh.Mesh`
fields that hold it, its width, its unit, the note a report gives when a mesh
lacks it, the name every command uses for it (``render --show``, ``view
--attribute``), how pictures label it and colour its scores (the 3-D view, the
study's charts, the Blender panel), and how a difference of two values reads in
that unit (:func:`pixel_error`). Which rules score an attribute is read from the
rule registry (``affinity.lint.scored_codes``), so a new rule on an attribute is
found without touching this table. Imports nothing at load (the command line reads the
names); the measures are imported when a difference is taken.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np


def _texel_difference(values: np.ndarray, reference: np.ndarray, texture_size) -> np.ndarray:
    """|du W, dv H| in texels."""
    from .measures import texels

    return texels(values - reference, texture_size)


def _color_difference(values: np.ndarray, reference: np.ndarray, texture_size) -> np.ndarray:
    """|d rgb| in 1/255 steps."""
    from .measures import color_steps

    return color_steps(values - reference)


def _normal_difference(values: np.ndarray, reference: np.ndarray, texture_size) -> np.ndarray:
    """The angle between two normals in degrees: atan2(|n x r|, n . r) (accurate for small angles)."""
    import numpy as np

    from .geometry import lengths

    cross = lengths(np.cross(values, reference))
    return np.degrees(np.arctan2(cross, np.einsum("nk,nk->n", values, reference)))


@dataclass(frozen=True, kw_only=True)
class Attribute:
    """Everything about one per-corner attribute.

    Attributes
    ----------
    field : the :class:`~affinity.mesh.Mesh` field of its values, ``"texcoords"``
    corner_index : the Mesh field indexing ``field`` per corner (``"corner_texcoord"``;
        ``"corner_vertex"`` for an attribute stored per position vertex)
    name : how every command and picture names it (``"uv"``, ``"color"``, ``"normal"``)
    aliases : other spellings accepted on the command line (``"colour"``)
    width : components per value: (T, width) float64
    unit : the unit a split error of it is measured in (``"texels"``, ``"1/255"``, ``"degrees"``)
    display_name : what prose calls it (``"texture coordinates"``, ``"vertex colours"``)
    label : what a picture's legend or axis calls it (``"uv"``, ``"colour"``)
    colormap : the matplotlib colour map its scores are drawn with (the 3-D view, the report's overview)
    unit_length : values are directions, scaled to unit length before measuring
    difference : ``difference(values, reference, texture_size) -> (N,)`` float64, the
        difference of (N, width) values against a reference in ``unit``
    """

    field: str
    corner_index: str
    name: str
    aliases: tuple[str, ...] = ()
    width: int
    unit: str
    display_name: str
    label: str
    colormap: str = "viridis"
    unit_length: bool = False
    difference: Callable[[np.ndarray, np.ndarray, object], np.ndarray]

    @property
    def per_vertex(self) -> bool:
        """Stored per position vertex (reached through ``corner_vertex``), not per corner."""
        return self.corner_index == "corner_vertex"

    @property
    def missing(self) -> str:
        """What a report says of a mesh without it: ``"no texture coordinates"``."""
        return f"no {self.display_name}"

    def legend(self, unit: str | None = None) -> str:
        """The title of a colour bar or axis of its scores in ``unit`` (default: the attribute's own; a
        reading may change it): ``"uv score (texels)"``."""
        return f"{self.label} score ({unit or self.unit})"


#: Every attribute by Mesh field, in the order scores and pictures prefer them.
ATTRIBUTES: dict[str, Attribute] = {
    attribute.field: attribute
    for attribute in (
        Attribute(field="texcoords", corner_index="corner_texcoord", name="uv", width=2, unit="texels",
                  display_name="texture coordinates", label="uv", difference=_texel_difference),
        Attribute(field="colors", corner_index="corner_vertex", name="color", aliases=("colour",), width=3,
                  unit="1/255", display_name="vertex colours", label="colour", difference=_color_difference),
        Attribute(field="normals", corner_index="corner_normal", name="normal", width=3, unit="degrees",
                  display_name="normals", label="normal", unit_length=True, difference=_normal_difference),
    )
}

#: Mesh field -> command-line name, for callers that only need the name.
ATTRIBUTE_NAMES = {field: attribute.name for field, attribute in ATTRIBUTES.items()}


def attribute_named(text: str) -> Attribute:
    """The attribute a command-line name or alias means (``"uv"``, ``"colour"``); KeyError for none."""
    for attribute in ATTRIBUTES.values():
        if text in (attribute.name, *attribute.aliases):
            return attribute
    raise KeyError(text)


def canonical_name(text: str) -> str:
    """``text`` with an alias replaced by the attribute's own name; anything else unchanged.

    >>> canonical_name("colour"), canonical_name("uv"), canonical_name("shaded")
    ('color', 'uv', 'shaded')
    """
    try:
        return attribute_named(text).name
    except KeyError:
        return text


#: The attributes a picture draws when nothing else decides, in order of preference (Mesh fields); a mesh with
#: none of them is shaded (its normals light it: drawn as colours they would hide the surface).
DRAWN_IN_ORDER = ("texcoords", "colors")


def drawn_attribute(mesh, preferred: str | None = None) -> str:
    """What a picture of ``mesh`` draws: the attribute ``preferred`` (a Mesh field, e.g. the one a finding is
    about) when it is one of :data:`DRAWN_IN_ORDER` and the mesh has it, else the first of those the mesh has,
    by its command-line name (``"uv"``, ``"color"``), else ``"shaded"``.

    >>> from types import SimpleNamespace
    >>> terrain = SimpleNamespace(texcoords=[(0, 0)], colors=[(1, 0, 0)], normals=None)
    >>> drawn_attribute(terrain), drawn_attribute(terrain, "colors"), drawn_attribute(terrain, "normals")
    ('uv', 'color', 'uv')
    >>> drawn_attribute(SimpleNamespace(texcoords=None, colors=None, normals=[(0, 0, 1)]))
    'shaded'
    """
    fields = ((preferred,) if preferred in DRAWN_IN_ORDER else ()) + DRAWN_IN_ORDER
    return next((ATTRIBUTES[field].name for field in fields if getattr(mesh, field) is not None), "shaded")


def pixel_error(values: np.ndarray, reference: np.ndarray, attribute: str, texture_size) -> np.ndarray:
    """Error of interpolated attributes against a reference's, in the lint's units.

    Parameters
    ----------
    values, reference : (N, K) float64, the attribute at N pixels
    attribute : the Mesh field they come from: ``"texcoords"``, ``"colors"`` or ``"normals"``
        (a key of :data:`ATTRIBUTES`)
    texture_size : (width, height) in texels, for texture coordinates

    Returns
    -------
    (N,) float64: |du, dv| in texels, |d rgb| in 1/255 steps, or the angle
    between the two normals in degrees (the attribute's ``difference``).
    """
    return ATTRIBUTES[attribute].difference(values, reference, texture_size)
