"""``affinity check --show-settings``: the resolved settings, written as an ``affinity.toml``.

One block per configuration source among the given paths, naming the paths it
governs and the file it came from. The keys are those :mod:`affinity.config`
reads, so a block can be saved as an ``affinity.toml`` as it is.
"""

from __future__ import annotations

import json
import math
from typing import TextIO

from ..config import Resolver
from ..rules import RULES, resolve_codes
from ..settings import Settings
from .names import printable


def _toml(value) -> str:
    """A TOML value: a basic string (control characters escaped, astral characters as
    they are: JSON's surrogate pairs are not TOML), a number, or a list of them."""
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ("inf" if value > 0 else "-inf" if value < 0 else "nan")
    if isinstance(value, int):
        return str(value)
    return "[" + ", ".join(map(_toml, value)) + "]"


def _comment(text: str) -> str:
    """``text`` on one comment line (a path may hold a newline)."""
    return "# " + text.replace("\r", " ").replace("\n", " ")


def _level(settings: Settings, code: str) -> str:
    """A ``[levels]`` value: ``"warning"``, or ``{error = 2.0}`` for a rule with a visibility threshold."""
    above = settings.error_above(code)
    return _toml(settings.level(code)) if above is None else f"{{error = {_toml(float(above))}}}"


def settings_toml(settings: Settings) -> list[str]:
    """The settings as ``affinity.toml`` lines, every rule's effective thresholds (flag and visibility) included."""
    lines = [
        f"select = {_toml(settings.select if settings.select is not None else ['ALL'])}",
        f"ignore = {_toml(settings.ignore or [])}",
        f"measure = {_toml(settings.measure)}",
        f"diagonal = {_toml(settings.diagonal)}",
        f"texture-size = {settings.texture_size}",
        f"subdivision = {_toml(settings.subdivision)}",
        f"profile = {_toml(settings.profile)}",
        f"fvar-interpolation = {_toml(settings.fvar_interpolation)}",
        f"visible-error = {_toml(float(settings.visible_error))}",
        f"visible-warning = {_toml(float(settings.visible_warning))}",
        f"visible-min-shift = {_toml(float(settings.visible_min_shift))}",
        f"exclude = {_toml(settings.exclude)}",
        f"extend-exclude = {_toml(settings.extend_exclude)}",
        "",
        "[thresholds]",
    ]
    lines += [f"{code} = {_toml(float(settings.threshold(code)))}"
              for code, rule in RULES.items() if rule.default_threshold is not None]
    lines += ["", "[levels]"]
    lines += [f"{code} = {_level(settings, code)}" for code in RULES]
    lines += ["", "[per-file-ignores]"]
    lines += [f"{_toml(glob)} = {_toml(codes)}" for glob, codes in settings.per_file_ignores.items()]
    return lines


def write_settings(resolver: Resolver, paths: list[str], out: TextIO) -> None:
    """Write the settings governing each of ``paths``, one block per configuration source."""
    governed: dict = {}
    for path in paths:
        resolved = resolver.resolve(path)
        governed.setdefault(resolved.source, (resolved, []))[1].append(path)
    for i, (resolved, names) in enumerate(governed.values()):
        settings = resolved.settings
        source = resolved.source or "no configuration file (defaults and command-line flags)"
        head = [
            _comment(f"settings for {', '.join(map(printable, names))}"),
            _comment(f"from {printable(str(source))}"),
            _comment(f"globs relative to {printable(str(settings.root)) if settings.root else '(none)'}"),
            _comment(f"rules enabled: {', '.join(resolve_codes(settings.select, settings.ignore))}"),
        ]
        out.write(("\n" if i else "") + "\n".join(head + settings_toml(settings)) + "\n")
