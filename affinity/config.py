"""Configuration files: find the one that governs a path, read and validate it.

A folder's configuration is ``affinity.toml`` (keys at the top level) or the
``[tool.affinity]`` table of ``pyproject.toml``; when a folder has both,
``affinity.toml`` wins. The file that governs a mesh is the first one found
walking up from the mesh's folder; a ``pyproject.toml`` without a
``[tool.affinity]`` table does not count, so the search goes on above it.

Keys (kebab-case, as in ruff)::

    select = ["Q1", "Q201"]          # rule codes or prefixes, "ALL"
    ignore = ["Q202"]
    threshold = 0.8                  # shorthand for thresholds.Q101
    measure = "error"                # or "centre", "barycentric" ("misplacement": old name of error)
    diagonal = "both"                # "02", "13", "shortest"
    texture-size = 2048
    subdivision = "auto"             # "cage", "level:2", "limit": which surface Q101-Q103 measure
    profile = "game"                 # "storm", "blender-viewport", "blender-render", "film": its level for auto
    fvar-interpolation = "cornersPlus1"  # OBJ/PLY/OFF uv rule when refined (USD meshes name their own)
    exclude = ["legacy", "wip/*.ply"]  # replaces the default skips (.git, node_modules, ...)
    extend-exclude = ["scratch"]     # adds to them
    [thresholds]                     # [tool.affinity.thresholds] in pyproject.toml
    Q102 = 3
    [levels]                         # [tool.affinity.levels]: error, warning or info
    Q203 = "warning"                 # every Q203 finding is a warning
    Q101 = {error = 3.0}             # an error above 3 texels, below it the rule's level (warning)
    [per-file-ignores]
    "scans/*" = ["Q202", "Q203"]
    "characters/*.obj::helper-*" = ["ALL"]   # path::group (OBJ g/o name, USD prim path)

Thresholds must be finite numbers and ``select`` must name at least one rule
(``ignore`` switches rules off): nothing here switches a check off silently.

Run-level keys, read only from the configuration of the current directory
(:meth:`Resolver.run_options`), never per file::

    scheduler = "tcp://scheduler:8786"   # or "env", "local:4": check on a Dask cluster
    cache = false                        # turn the result cache off

Globs are relative to the configuration file's folder (see
:func:`affinity.settings.glob_matches`).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

from .errors import UsageError
from .rules import RULES
from .settings import (
    DIAGONALS,
    FVAR_INTERPOLATIONS,
    MEASURES,
    PROFILES,
    Settings,
    measure_name,
    subdivision_name,
    unknown_codes,
    unknown_levels,
    unmeasured_codes,
    unthresholded_codes,
)

CONFIG_NAMES = ("affinity.toml", "pyproject.toml")


class ConfigError(UsageError):
    """A configuration file that cannot be read or says something invalid (exit 2)."""


@dataclass(frozen=True)
class Resolved:
    """The settings for a path and the configuration file they came from (None: defaults only)."""

    settings: Settings
    source: Path | None


def _read_text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"{path}: cannot read configuration: {err}") from None


def _parse_toml(path: Path, text: str) -> dict:
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(f"{path}: invalid TOML: {err}") from None


def _table(path: Path) -> dict | None:
    """The affinity table of a configuration file, or None when a pyproject.toml has none."""
    text = _read_text(path)
    if path.name != "pyproject.toml":
        return _parse_toml(path, text)
    if "affinity" not in text:
        return None  # cheap pre-check: most pyproject files never mention us
    table = _parse_toml(path, text).get("tool", {}).get("affinity")
    return table if isinstance(table, dict) else None


def find_config(folder: Path) -> Path | None:
    """The configuration file governing ``folder``: the nearest one at or above it."""
    for candidate in (folder, *folder.parents):
        for name in CONFIG_NAMES:
            path = candidate / name
            if path.is_file() and _table(path) is not None:
                return path
    return None


def _codes(value, where: str) -> list[str]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{where}: expected a list of rule codes, e.g. [\"{next(iter(RULES))}\"]")
    codes = [v.strip().upper() for v in value]
    unknown = unknown_codes(codes)
    if unknown:
        raise ConfigError(f"{where}: unknown rule {', '.join(unknown)}")
    return codes


def _number(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{where}: expected a number")
    if not math.isfinite(value):
        raise ConfigError(f"{where}: expected a finite number, not {value} (use ignore to switch a rule off)")
    return float(value)


def _selection(value, where: str) -> list[str]:
    codes = _codes(value, where)
    if not codes:
        raise ConfigError(f"{where}: selects no rule (use ignore to switch rules off)")
    return codes


def _levels(value, where: str) -> dict[str, str]:
    """The string entries of ``[levels]`` (one level for every finding of the rule)."""
    if not isinstance(value, dict):
        raise ConfigError(f"{where}: expected a table of rule code = \"error\" | \"warning\" | \"info\" "
                          "or {error = number}")
    levels = {str(code).upper(): level for code, level in value.items() if not isinstance(level, dict)}
    bad = unknown_levels(levels)
    if bad:
        raise ConfigError(f"{where}: {', '.join(bad)} (expected a rule code = \"error\", \"warning\" or \"info\")")
    return levels


def _visible(value, where: str) -> dict[str, float]:
    """The table entries of ``[levels]``: ``Q101 = {error = 2.0}``, the visibility threshold."""
    visible = {}
    for code, entry in value.items() if isinstance(value, dict) else ():
        if not isinstance(entry, dict):
            continue
        if set(entry) != {"error"}:
            raise ConfigError(f"{where}.{code}: expected {{error = number}} (findings above it are errors)")
        visible[str(code).upper()] = _number(entry["error"], f"{where}.{code}.error")
    bad = unmeasured_codes(list(visible))
    if bad:
        raise ConfigError(f"{where}: {', '.join(bad)} is not a rule with a threshold to be above")
    return visible


def _choice(value, choices: tuple[str, ...], where: str) -> str:
    if value not in choices:
        raise ConfigError(f"{where}: expected one of {', '.join(map(repr, choices))}")
    return value


def _measure(value, where: str) -> str:
    measure = measure_name(value, where) if isinstance(value, str) else None
    return measure if measure is not None else _choice(value, MEASURES, where)


def _thresholds(value, where: str) -> dict[str, float]:
    if not isinstance(value, dict):
        raise ConfigError(f"{where}: expected a table of rule code = number")
    thresholds = {str(code).upper(): _number(v, f"{where}.{code}") for code, v in value.items()}
    bad = unthresholded_codes(list(thresholds))
    if bad:
        raise ConfigError(f"{where}: {', '.join(bad)} is not a rule with a threshold")
    return thresholds


def _texture_size(value, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
        raise ConfigError(f"{where}: expected a positive number of pixels")
    return value


def _non_negative(value, where: str) -> float:
    number = _number(value, where)
    if number < 0:
        raise ConfigError(f"{where}: expected a number at or above 0")
    return number


def _globs(value, where: str) -> list[str]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{where}: expected a list of path globs")
    return list(value)


def _per_file_ignores(value, where: str) -> dict[str, list[str]]:
    if not isinstance(value, dict):
        raise ConfigError(f"{where}: expected a table of glob = [rule codes]")
    return {glob: _codes(codes, f"{where}.{glob!r}") for glob, codes in value.items()}


def _subdivision(value, where: str) -> str:
    name = subdivision_name(value) if isinstance(value, str) else None
    if name is None:
        raise ConfigError(f"{where}: expected cage, auto, limit or level:N")
    return name


#: TOML key -> (Settings field, validator(value, where)).
_KEYS = {
    "select": ("select", _selection),
    "ignore": ("ignore", _codes),
    "thresholds": ("thresholds", _thresholds),
    "measure": ("measure", _measure),
    "diagonal": ("diagonal", lambda v, where: _choice(v, DIAGONALS, where)),
    "texture-size": ("texture_size", _texture_size),
    "visible-error": ("visible_error", _non_negative),
    "visible-warning": ("visible_warning", _non_negative),
    "visible-min-shift": ("visible_min_shift", _non_negative),
    "exclude": ("exclude", _globs),
    "extend-exclude": ("extend_exclude", _globs),
    "levels": ("levels", _levels),
    "per-file-ignores": ("per_file_ignores", _per_file_ignores),
    "subdivision": ("subdivision", _subdivision),
    "profile": ("profile", lambda v, where: _choice(v, tuple(PROFILES), where)),
    "fvar-interpolation": ("fvar_interpolation", lambda v, where: _choice(v, FVAR_INTERPOLATIONS, where)),
}


def _scheduler(value, where: str) -> str:
    if not isinstance(value, str) or not value.strip():
        raise ConfigError(f"{where}: expected a scheduler address, \"env\" or \"local:N\"")
    return value.strip()


def _flag(value, where: str) -> bool:
    if not isinstance(value, bool):
        raise ConfigError(f"{where}: expected true or false")
    return value


#: Run-level TOML keys -> validator; they apply to a whole run, so they are not Settings.
_RUN_KEYS = {"scheduler": _scheduler, "cache": _flag}


def read_config(path: Path) -> dict:
    """The validated options of a configuration file as Settings field names -> values.

    ``root`` is the file's folder; ``threshold`` becomes ``thresholds["Q101"]``.
    """
    table = _table(path)
    if table is None:
        raise ConfigError(f"{path}: no [tool.affinity] table")
    prefix = f"{path}: " + ("[tool.affinity] " if path.name == "pyproject.toml" else "")
    options: dict = {"root": os.path.abspath(path.parent)}
    for key, value in table.items():
        if key == "threshold" or key in _RUN_KEYS:
            continue
        if key not in _KEYS:
            raise ConfigError(f"{prefix}unknown key {key!r} (known: threshold, {', '.join([*_KEYS, *_RUN_KEYS])})")
        name, validate = _KEYS[key]
        options[name] = validate(value, prefix + key)
        if key == "levels":
            options["visible"] = _visible(value, prefix + key)
    for key in _RUN_KEYS.keys() & table.keys():
        _RUN_KEYS[key](table[key], prefix + key)
    if "threshold" in table:
        from .rules.affinity import UV_DISAFFINE

        if UV_DISAFFINE in options.get("thresholds", {}):
            raise ConfigError(f"{prefix}threshold and thresholds.{UV_DISAFFINE} both set the {UV_DISAFFINE} threshold")
        options.setdefault("thresholds", {})[UV_DISAFFINE] = _number(table["threshold"], prefix + "threshold")
    return options


class Resolver:
    """Settings per path: defaults, then the governing configuration file, then the flags.

    Parameters
    ----------
    overrides : dict
        Settings field name -> value for every flag given on the command line.
    config : path or None
        Use this file for every path instead of searching (``--config``).
    isolated : bool
        Ignore configuration files altogether (``--isolated``).
    """

    def __init__(self, overrides: dict, config: str | None = None, isolated: bool = False):
        self._overrides = overrides
        self._explicit = None if config is None else Path(config)
        self._isolated = isolated
        self._by_folder: dict[Path, Path | None] = {}
        self._by_source: dict[Path | None, Resolved] = {}
        if self._explicit is not None and not self._explicit.is_file():
            raise ConfigError(f"{config}: no such configuration file")

    def _source(self, folder: Path) -> Path | None:
        if self._isolated:
            return None
        if self._explicit is not None:
            return self._explicit
        if folder not in self._by_folder:
            self._by_folder[folder] = find_config(folder)
        return self._by_folder[folder]

    def resolve(self, path: str) -> Resolved:
        """The settings governing ``path`` (a file, or a folder for everything in it)."""
        absolute = Path(os.path.abspath(path))
        source = self._source(absolute if absolute.is_dir() else absolute.parent)
        if source not in self._by_source:
            settings = Settings() if source is None else Settings().updated(read_config(source))
            self._by_source[source] = Resolved(settings.updated(self._overrides), source)
        return self._by_source[source]

    def run_options(self) -> dict:
        """The run-level keys (``scheduler``, ``cache``) of the configuration governing the current directory."""
        source = self._source(Path(os.path.abspath(os.curdir)))
        if source is None:
            return {}
        table = _table(source) or {}
        prefix = f"{source}: " + ("[tool.affinity] " if source.name == "pyproject.toml" else "")
        return {key: _RUN_KEYS[key](table[key], prefix + key) for key in _RUN_KEYS.keys() & table.keys()}


def file_settings(path: str) -> Settings:
    """The settings ``affinity check PATH`` lints ``path`` with when no flag is given: the governing
    configuration file's (per-file ignores applied), else the defaults; the defaults too for a path
    that names no file (a mesh built in memory, a built-in scene)."""
    if not os.path.isfile(path):
        return Settings()
    return Resolver({}).resolve(path).settings.for_file(path)
