"""Help text and messages that name rules, made from the registry (no module outside affinity/rules/ writes a
rule code): the command line's examples, the scored rules' span, and the Q901 line."""

from __future__ import annotations

from .affinity import UV_DISAFFINE
from .file import UNREADABLE
from .registry import RULES, code_spans


def scored() -> list[str]:
    """The scored rules' codes (:attr:`.registry.Rule.scored`), in code order."""
    return [code for code, rule in RULES.items() if rule.scored]


def scored_span() -> str:
    """``Q101-Q103``: the scored rules (the ones ``affinity fix`` refines away and ``--measure`` reads)."""
    return code_spans(scored())


def select_example() -> str:
    """``Q1,Q201``: a prefix and a code of another hundred, as ``--select`` takes them."""
    first = next(iter(RULES))
    other = next(code for code in RULES if code[:2] != first[:2])
    return f"{first[:2]},{other}"


def threshold_example() -> str:
    """``0.8 or Q102=3``: a bare threshold and one given to a rule by code."""
    return f"0.8 or {scored()[1]}=3"


def bare_threshold_help() -> str:
    """What a bare ``--threshold`` number sets."""
    from ..attributes import ATTRIBUTES

    return (f"flag above VALUE: a bare number sets {UV_DISAFFINE} ({ATTRIBUTES[RULES[UV_DISAFFINE].attribute].name}); "
            "repeat CODE=VALUE for other rules")


def measure_help() -> str:
    """``--measure``'s help: which rules each reading applies to."""
    barycentric = code_spans(code for code, rule in RULES.items() if "barycentric" in rule.readings)
    return (f"{scored_span()} reading: the split's largest error (default), its shift at the centre, "
            f"or ({barycentric}) the paper's barycentric score")


def fix_left_code(reason: str) -> str:
    """The code of the rule whose flagged quads ``affinity fix`` leaves with ``reason`` (``Q202``: nonplanar)."""
    return next(code for code, rule in RULES.items() if rule.fix_leaves == reason)


def unreadable_line(where: str, reason: str, line: int | None = None) -> str:
    """The Q901 line (design.md): ``where:line: Q901 unreadable: reason``, or ``where: Q901 ...`` without a
    line (a USD prim); the reason on one line. ``where`` is written as given: a file name comes escaped
    (:func:`affinity.loaders.names.printable`)."""
    at = where if line is None else f"{where}:{line}"
    return f"{at}: {UNREADABLE.code} {UNREADABLE.name}: {' '.join(reason.split())}"
