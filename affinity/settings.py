"""Resolved lint settings: defaults here; configuration files and flags layer on top.

Layering (lowest first): the defaults of :class:`Settings`, the configuration
file that governs a path (``affinity.toml`` or ``[tool.affinity]`` in
``pyproject.toml``, see :mod:`affinity.config`), then the command-line flags.
Each layer replaces the values it names; ``thresholds`` merge per rule, so a
flag ``--threshold Q102=3`` keeps a configured Q101 threshold.

Path globs (``exclude``, the keys of ``per_file_ignores``) are relative to
``root``, the folder of the configuration file that set them, and match the
file's path relative to it with ``/`` separators (:func:`glob_matches`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from fnmatch import fnmatchcase

from .rules import LEVELS, RULES

MEASURES = ("error", "centre", "barycentric")
#: Old measure names still accepted, with one warning line: name -> the measure it now means.
DEPRECATED_MEASURES = {"misplacement": "error"}
#: Folders a directory walk never enters unless ``exclude`` is set (``extend-exclude`` adds to them): ruff's
#: default excludes, which name version-control metadata, virtual environments, tool caches and build output
#: (any of them can hold other projects' meshes or schema files), and ``__pycache__``. They apply below the
#: paths a run is given, never to a path named on the command line.
DEFAULT_EXCLUDE = (
    ".bzr", ".direnv", ".eggs", ".git", ".git-rewrite", ".hg", ".ipynb_checkpoints", ".mypy_cache", ".nox",
    ".pants.d", ".pyenv", ".pytest_cache", ".pytype", ".ruff_cache", ".svn", ".tox", ".venv", ".vscode",
    "__pycache__", "__pypackages__", "_build", "buck-out", "build", "dist", "node_modules", "site-packages", "venv",
)
DIAGONALS = ("both", "02", "13", "shortest")
#: Renderer profiles -> the subdivision level they draw (0: the cage; "limit": the limit surface).
PROFILES = {"game": 0, "storm": 0, "blender-viewport": 1, "blender-render": 2, "film": "limit"}
#: Face-varying linear-interpolation rules (USD's ``faceVaryingLinearInterpolation``, OpenSubdiv's Sdc).
FVAR_INTERPOLATIONS = ("none", "cornersOnly", "cornersPlus1", "cornersPlus2", "boundaries", "all")


def subdivision_name(text: str) -> str | None:
    """``text`` as a ``subdivision`` setting (``cage``, ``auto``, ``limit`` or ``level:N``, N >= 0), else None."""
    if text in ("cage", "auto", "limit"):
        return text
    head, _, number = text.partition(":")
    return f"level:{int(number)}" if head == "level" and number.isdigit() else None


def measure_name(name: str, where: str) -> str | None:
    """The measure ``name`` means (None for an unknown name); a deprecated name gets one
    warning line on stderr, prefixed by ``where`` (the flag or the configuration key)."""
    if name in DEPRECATED_MEASURES:
        import sys

        sys.stderr.write(f"{where}: warning: {name!r} is deprecated, use {DEPRECATED_MEASURES[name]!r}\n")
        return DEPRECATED_MEASURES[name]
    return name if name in MEASURES else None


@dataclass
class Settings:
    """What ``affinity check`` measures, where it draws the line, and which files it skips.

    ``thresholds`` maps rule codes to thresholds in the rule's unit; rules not in
    it use their default. ``measure`` picks the reading used for Q101-Q103:
    ``"error"`` (the split's largest error over the quad, attribute units),
    ``"centre"`` (the split's shift at the corner mean) or ``"barycentric"``
    (the paper's dimensionless score; defined for uv only, so Q102/Q103 read
    ``error`` under it).
    ``diagonal`` picks which split the affinity test measures: ``"both"``,
    ``"02"``, ``"13"`` or ``"shortest"``. ``exclude`` lists globs of files not
    to check; ``per_file_ignores`` maps a glob to rule codes (or prefixes)
    ignored in the files it matches; both are relative to ``root``. A key
    ``"path::group"`` ignores the codes only in the groups (OBJ ``g``/``o``
    names, USD prim paths) its second glob matches; :meth:`for_file` turns those
    into ``group_ignores``, (group glob, codes) pairs. ``levels`` maps rule codes
    to the level all their findings get (``error``, ``warning``, ``info``), over the
    rule's default. ``visible`` maps measured rules to their visibility threshold
    (configured as ``[levels] Q101 = {error = 2.0}``): a finding above it is an
    ``error``, one between the flag threshold and it gets the rule's level; a
    rule in ``levels`` gets that one level whatever its values.
    ``visible_error``, ``visible_warning`` (1/255 steps, degrees for normal maps) and
    ``visible_min_shift`` (texels) level Q101's findings read through a decoded texture
    (design.md, "The visible reading"; :attr:`visible_limits`).
    ``subdivision`` (``cage``, ``auto``, ``level:N``, ``limit``) and ``profile`` (:data:`PROFILES`) say which
    surface Q101-Q103 measure (:attr:`subdivision_level`); ``fvar_interpolation`` is the face-varying rule
    of meshes whose file names none (OBJ, PLY, OFF).
    """

    select: list[str] | None = None
    ignore: list[str] | None = None
    thresholds: dict[str, float] = field(default_factory=dict)
    measure: str = "error"
    diagonal: str = "both"
    texture_size: int = 1024
    visible_error: float = 8.0
    visible_warning: float = 2.0
    visible_min_shift: float = 1.0
    exclude: list[str] = field(default_factory=lambda: list(DEFAULT_EXCLUDE))
    per_file_ignores: dict[str, list[str]] = field(default_factory=dict)
    levels: dict[str, str] = field(default_factory=dict)
    visible: dict[str, float] = field(default_factory=dict)
    extend_exclude: list[str] = field(default_factory=list)
    root: str | None = None
    group_ignores: list[tuple[str, list[str]]] = field(default_factory=list)
    subdivision: str = "auto"
    profile: str = "game"
    fvar_interpolation: str = "cornersPlus1"

    def subdivision_level(self, scheme_subdivides: bool) -> int | str:
        """The level Q101-Q103 measure a mesh at (0: the cage, ``"limit"``): ``level:N`` and ``limit`` as
        they say, ``cage`` 0, ``auto`` the profile's level where the mesh's own scheme subdivides (an OBJ,
        PLY or OFF mesh has none: its cage)."""
        if self.subdivision.startswith("level:"):
            return int(self.subdivision.partition(":")[2])
        if self.subdivision == "limit":
            return "limit"
        if self.subdivision == "cage" or not scheme_subdivides:
            return 0
        return PROFILES[self.profile]

    @property
    def split_measure(self) -> str:
        """The reading of Q102/Q103 (and of Q101 unless barycentric): ``error`` or ``centre``."""
        return "centre" if self.measure == "centre" else "error"

    @property
    def visible_limits(self):
        """The ``visible-*`` settings as :class:`affinity.textures.visible.VisibleLimits`."""
        from .textures.visible import VisibleLimits

        return VisibleLimits(self.visible_error, self.visible_warning, self.visible_min_shift)

    def measure_of(self, code: str) -> str | None:
        """The reading a finding of a scored rule (Q101-Q103) was measured in, else None: the
        settings' measure where the rule has that reading, else the split's (barycentric is uv only)."""
        rule = RULES[code]
        if not rule.scored:
            return None
        return self.measure if self.measure in rule.readings else self.split_measure

    def threshold(self, code: str) -> float | None:
        """The threshold of rule ``code``: the configured one, else the rule's default for the reading."""
        if code in self.thresholds:
            return self.thresholds[code]
        return RULES[code].default_for(self.measure)

    def level(self, code: str) -> str:
        """The level of rule ``code``'s findings: the configured one, else the rule's."""
        return self.levels.get(code, RULES[code].level)

    def error_above(self, code: str) -> float | None:
        """The visibility threshold of rule ``code``: above it a finding is an ``error``; None where
        ``levels`` fixes the rule's level or the rule (under this reading) has none."""
        if code in self.levels:
            return None
        return self.visible.get(code, RULES[code].visible_for(self.measure))

    def updated(self, options: dict) -> Settings:
        """A copy with ``options`` (field name -> value) applied on top; thresholds, levels and
        visibility thresholds merge per rule (a rule given one kind of level drops the other)."""
        thresholds = {**self.thresholds, **options.get("thresholds", {})}
        new_levels, new_visible = options.get("levels", {}), options.get("visible", {})
        levels = {**{c: v for c, v in self.levels.items() if c not in new_visible}, **new_levels}
        visible = {**{c: v for c, v in self.visible.items() if c not in new_levels}, **new_visible}
        return replace(self, **{**options, "thresholds": thresholds, "levels": levels, "visible": visible})

    def relative(self, path: str) -> str | None:
        """``path`` relative to ``root`` with ``/`` separators, or None when it lies outside."""
        if self.root is None:
            return None
        rel = os.path.relpath(os.path.abspath(path), self.root)
        return None if rel.startswith("..") else rel.replace(os.sep, "/")

    @property
    def default_exclude(self) -> list[str]:
        """The default folder names still in force (none once ``exclude`` is configured)."""
        return list(DEFAULT_EXCLUDE) if self.exclude == list(DEFAULT_EXCLUDE) else []

    @property
    def configured_exclude(self) -> list[str]:
        """The ``exclude`` and ``extend-exclude`` globs a configuration or flag set (not the defaults)."""
        return [*(self.exclude if not self.default_exclude else []), *self.extend_exclude]

    def is_excluded(self, path: str) -> bool:
        """Whether a configured ``exclude`` or ``extend-exclude`` glob matches ``path``, a path named on the
        command line: the default folder names apply only inside the folders a run walks."""
        rel = self.relative(path)
        return rel is not None and any(glob_matches(pattern, rel) for pattern in self.configured_exclude)

    def for_file(self, path: str) -> Settings:
        """The settings to lint ``path`` with: ``ignore`` extended by the matching per-file
        ignores, ``group_ignores`` set from the matching ``path::group`` keys."""
        rel = self.relative(path)
        extra, groups = [], []
        for key, codes in self.per_file_ignores.items():
            pattern, _, group = key.partition("::")
            if rel is None or not glob_matches(pattern, rel):
                continue
            if group:
                groups.append((group, list(codes)))
            else:
                extra += codes
        if not extra and not groups:
            return self
        return replace(self, ignore=[*(self.ignore or []), *extra], group_ignores=groups)


def glob_matches(pattern: str, rel: str) -> bool:
    """Whether a path glob matches the relative path ``rel`` (``/``-separated).

    A pattern without ``/`` matches any single component (``"*.ply"`` any PLY
    file, ``"legacy"`` everything in a folder named legacy, at any depth). A
    pattern with ``/`` is anchored at the root and matches the path or one of
    its folders (``"assets/old"``, ``"assets/*/wip/*.obj"``); ``*`` crosses
    folders and ``**/`` may also match no folder at all.

    >>> glob_matches("*.ply", "a/b/c.ply"), glob_matches("legacy", "x/legacy/c.obj")
    (True, True)
    >>> glob_matches("assets/old", "assets/old/c.obj"), glob_matches("assets/old", "x/assets/old/c.obj")
    (True, False)
    >>> glob_matches("assets/**/c.obj", "assets/c.obj")
    True
    """
    parts = rel.split("/")
    pattern = pattern.strip("/")
    if "/" not in pattern:
        return any(fnmatchcase(part, pattern) for part in parts)
    variants = {pattern, pattern.replace("**/", "")}
    prefixes = ("/".join(parts[:i]) for i in range(1, len(parts) + 1))
    return any(fnmatchcase(prefix, v) for prefix in prefixes for v in variants)


def unknown_codes(prefixes: list[str]) -> list[str]:
    """The entries of ``prefixes`` that select no rule (``"ALL"`` and any prefix of a code are fine)."""
    return [p for p in prefixes if p != "ALL" and not any(code.startswith(p) for code in RULES)]


def unknown_levels(levels: dict) -> list[str]:
    """``"CODE = level"`` entries of ``levels`` that name no lint rule or no level."""
    return [f"{code} = {level!r}" for code, level in levels.items() if code not in RULES or level not in LEVELS]


def unthresholded_codes(codes: list[str]) -> list[str]:
    """The entries of ``codes`` that are not rules with a threshold."""
    return [c for c in codes if c not in RULES or RULES[c].default_threshold is None]


def unmeasured_codes(codes: list[str]) -> list[str]:
    """The entries of ``codes`` that cannot take a visibility threshold (not rules flagging values above one)."""
    return [c for c in codes if c not in RULES or RULES[c].default_threshold is None or RULES[c].flags != "above"]
