"""Every quad's affinity score for one attribute, not just the flagged ones.

The lint keeps only quads above a threshold; the histogram and the 3-D overview
need the whole distribution. Running the lint rule with its threshold at -inf
gives exactly the rule's own values for every measured quad, so the report can
never disagree with ``affinity check`` about a score.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..mesh import Mesh
from ..settings import Settings

#: Rule code -> (attribute as the report names it, the Mesh field that holds it).
SCORED_ATTRIBUTES = {"Q101": ("uv", "texcoords"), "Q102": ("colour", "colors"), "Q103": ("normal", "normals")}


@dataclass
class QuadScores:
    """One rule's reading for every quad that has the attribute at all four corners.

    Attributes
    ----------
    code : rule code, ``"Q101"``, ``"Q102"`` or ``"Q103"``
    attribute : ``"uv"``, ``"colour"`` or ``"normal"``
    unit : the values' unit, e.g. ``"texels"``
    threshold : the rule flags values above it
    faces : (n,) int64, face index in file order
    values : (n,) float64, the measured score; quads the rule cannot measure
        (NaN, e.g. a missing corner attribute) are not listed
    """

    code: str
    attribute: str
    unit: str
    threshold: float
    faces: np.ndarray
    values: np.ndarray

    @property
    def flagged(self) -> np.ndarray:
        """(n,) bool: the quads the rule flags."""
        return self.values > self.threshold


def scored_codes(mesh: Mesh) -> list[str]:
    """The affinity rules (Q101-Q103) whose attribute the mesh has."""
    return [code for code, (_, field) in SCORED_ATTRIBUTES.items() if getattr(mesh, field) is not None]


def shown_code(mesh: Mesh) -> str | None:
    """The rule of the attribute renders show by default (uv, else colours, else normals), or None."""
    codes = scored_codes(mesh)
    return codes[0] if codes else None


def unit_of(code: str, settings: Settings) -> str:
    """The unit of ``code``'s values under ``settings`` (Q101 is unitless in the barycentric reading)."""
    from ..rules import RULES

    if code == "Q101" and settings.measure == "barycentric":
        return "barycentric score"
    return RULES[code].unit


def quad_scores(mesh: Mesh, settings: Settings, code: str) -> QuadScores:
    """Score every quad of ``mesh`` with the affinity rule ``code`` (as ``settings`` configure it)."""
    from ..lint import lint_mesh

    everything = replace(settings, select=[code], ignore=[], thresholds={**settings.thresholds, code: -np.inf})
    hits = lint_mesh(mesh, everything)
    faces = hits[0].faces if hits else np.zeros(0, dtype=np.int64)
    values = hits[0].values if hits else np.zeros(0)
    attribute = SCORED_ATTRIBUTES[code][0]
    return QuadScores(code, attribute, unit_of(code, settings), settings.threshold(code), faces, values)
