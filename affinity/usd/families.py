"""The validator families: which rules each UsdValidation validator and NVIDIA rule runs.

One validator per rule family (:data:`affinity.rules.FAMILIES`), named after it, running the rules that
name it (:attr:`affinity.rules.Rule.family`); a family whose rules are all scored carries a fixer
(``affinity fix``'s refinement). Error names are the rule names (``uv-disaffine``), so a fixer is tied to
its rule's errors. The plug-in's ``plugInfo.json`` lists the same families (a test compares them).
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


def families() -> tuple[Family, ...]:
    """Every registered family with rules, from the rule registry as it is now (a rule registered at run time
    is reported by its family)."""
    from ..rules import FAMILIES, RULES, family_codes, family_doc

    made = []
    for name in FAMILIES:
        codes = family_codes(name)
        if codes:
            made.append(Family(name, codes, all(RULES[code].scored for code in codes), family_doc(name)))
    return tuple(made)


def unreadable_family() -> str:
    """The family that says why a prim (or its stage) cannot be read: Q901's."""
    from ..rules import UNREADABLE

    return UNREADABLE.family

