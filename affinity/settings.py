"""Resolved lint settings (defaults here; files and flags layer on top)."""

from __future__ import annotations

from dataclasses import dataclass, field

from .rules import RULES

#: The paper's own tolerance for the dimensionless barycentric reading.
BARYCENTRIC_TOLERANCE = 0.01


@dataclass
class Settings:
    """What ``affinity check`` measures and where it draws the line.

    ``thresholds`` maps rule codes to thresholds in the rule's unit; rules not in
    it use their default. ``measure`` picks the reading used for Q101-Q103:
    ``"misplacement"`` (attribute units) or ``"barycentric"`` (the paper's
    dimensionless score; defined for uv only, so Q102/Q103 keep misplacement). ``diagonal`` picks which split the affinity
    test measures: ``"both"``, ``"02"``, ``"13"`` or ``"shortest"``.
    """

    select: list[str] | None = None
    ignore: list[str] | None = None
    thresholds: dict[str, float] = field(default_factory=dict)
    measure: str = "misplacement"
    diagonal: str = "both"
    texture_size: int = 1024

    def threshold(self, code: str) -> float | None:
        if code in self.thresholds:
            return self.thresholds[code]
        if self.measure == "barycentric" and code == "Q101":
            return BARYCENTRIC_TOLERANCE
        return RULES[code].default_threshold
