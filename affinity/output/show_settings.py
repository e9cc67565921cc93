"""``affinity check --show-settings``: the resolved settings, written as an ``affinity.toml``.

One block per configuration source among the given paths, naming the paths it
governs and the file it came from. The keys are those :mod:`affinity.config`
reads, so a block can be saved as an ``affinity.toml`` as it is.
"""

from __future__ import annotations

import json
from typing import TextIO

from ..config import Resolver
from ..rules import RULES, resolve_codes
from ..settings import Settings


def _toml(value) -> str:
    return json.dumps(value)  # JSON strings, numbers and lists of them are TOML too


def settings_toml(settings: Settings) -> list[str]:
    """The settings as ``affinity.toml`` lines, every rule's effective threshold included."""
    lines = [
        f"select = {_toml(settings.select if settings.select is not None else ['ALL'])}",
        f"ignore = {_toml(settings.ignore or [])}",
        f"measure = {_toml(settings.measure)}",
        f"diagonal = {_toml(settings.diagonal)}",
        f"texture-size = {settings.texture_size}",
        f"exclude = {_toml(settings.exclude)}",
        "",
        "[thresholds]",
    ]
    lines += [f"{code} = {_toml(settings.threshold(code))}"
              for code, rule in RULES.items() if rule.default_threshold is not None]
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
            f"# settings for {', '.join(names)}",
            f"# from {source}",
            f"# globs relative to {settings.root or '(none)'}",
            f"# rules enabled: {', '.join(resolve_codes(settings.select, settings.ignore))}",
        ]
        out.write(("\n" if i else "") + "\n".join(head + settings_toml(settings)) + "\n")
