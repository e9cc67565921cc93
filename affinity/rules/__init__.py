"""The rules: one registry (:mod:`.registry`), each rule's record beside its check.

- :mod:`.affinity`: Q101-Q103, the attribute is not an affine image of the positions;
- :mod:`.shape`: Q201-Q204, the quad's own shape;
- :mod:`.file`: Q205 no-faces, and Q901 unreadable (documented, never linted);
- :mod:`.texture`: Q301-Q302, the quad in texture space;
- :mod:`.subdivided`: Q106, what subdivision does to the texture (UV drift);
- :mod:`.docs`: a rule's page and the README's table, from the registry.

A rule is its check decorated with ``@rule(code=..., name=..., ...)``, one signature for
all, ``check(context) -> Measured`` (:mod:`.registry`); the check's docstring is the
rule's page (:func:`.registry.page_fields`). Adding a rule touches
its module only: lint, the report, SARIF, ``affinity rules`` and the README table
read :data:`RULES`.
"""

from . import affinity, file, shape, subdivided, texture  # noqa: F401  each registers its rules
from .docs import SECTIONS, number_spec, number_text, rule_page, rules_table, threshold_text, with_unit
from .file import UNREADABLE
from .registry import (
    FAMILIES,
    LEVELS,
    RULES,
    Measured,
    Rule,
    family_codes,
    family_doc,
    fix_left_rules,
    fix_uncut_rules,
    masking_rules,
    page_fields,
    register,
    register_family,
    resolve_codes,
    rule,
    unregister,
)


def find_rule(key: str) -> Rule | None:
    """The rule (Q901 included) with code or name ``key`` (case-insensitive), or None."""
    key = key.strip()
    for candidate in (*RULES.values(), UNREADABLE):
        if key.upper() == candidate.code or key.lower() == candidate.name:
            return candidate
    return None


__all__ = ["FAMILIES", "LEVELS", "RULES", "SECTIONS", "UNREADABLE", "Measured", "Rule", "family_codes", "family_doc",
           "find_rule", "fix_left_rules", "fix_uncut_rules", "masking_rules", "number_spec", "number_text", "page_fields", "register",
           "register_family",
           "resolve_codes", "rule", "rule_page", "rules_table", "threshold_text", "unregister", "with_unit"]
