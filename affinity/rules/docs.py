"""A rule's page and the README's rule table, written from the registry.

The page follows ruff's layout: What it does / Why it matters / Example (the
rule's OBJ and the line ``affinity check`` prints for it) / Use instead (the
example fixed, which ``affinity check`` finds clean) / References / How to fix;
it ends with the fix a modelling tool can apply (design.md).
"""

from __future__ import annotations

import textwrap

from .file import UNREADABLE
from .registry import RULES, Rule

#: The prose sections of every page, in order: (heading, Rule attribute).
SECTIONS = (
    ("What it does", "what"),
    ("Why it matters", "why"),
    ("Example", "example"),
    ("Use instead", "use_instead"),
    ("References", "references"),
    ("How to fix", "fix"),
)


def threshold_text(rule: Rule) -> str:
    """``"0.5 texels"``, or ``""`` for a rule without a threshold."""
    return "" if rule.default_threshold is None else with_unit(number_text(rule.default_threshold), rule.unit)


def level_text(rule: Rule) -> str:
    """``"warning"``, or ``"warning; error above 2 texels"`` for a rule with a visibility threshold."""
    if rule.visible_threshold is None:
        return rule.level
    return f"{rule.level}; error above {with_unit(number_text(rule.visible_threshold), rule.unit)}"


#: Significant digits of a measured number for people: findings, rule pages, the report, ``affinity fix``.
DIGITS = 4


def number_spec(digits: int = DIGITS) -> str:
    """The ``%`` format of a measured number with ``digits`` significant digits, for :func:`number_text` and
    for writers that format a column of numbers at once (:func:`affinity.output.rows.floats`)."""
    return f"%.{digits}g"


def number_text(value: float, digits: int = DIGITS) -> str:
    """A measured number for people: ``digits`` significant digits, no exponent for everyday sizes.

    >>> number_text(175.6854), number_text(2.0), number_text(1e-9), number_text(0.12345, digits=3)
    ('175.7', '2', '1e-09', '0.123')
    """
    return number_spec(digits) % value


def with_unit(number: str, unit: str) -> str:
    """``"0.5 texels"``; a unit ``1/N`` reads as a fraction (``"2/255"``, not ``"2 1/255"``)."""
    if unit.startswith("1/"):
        return number + unit[1:]
    return f"{number} {unit}".rstrip()


def _file(obj: str, outcome: str, markdown: bool) -> str:
    """An input file of the page, then ``outcome`` (if any): what ``affinity check`` makes of it."""
    obj = obj.rstrip("\n")
    block = f"```\n{obj}\n```" if markdown else textwrap.indent(obj, "        ")
    return block + (f"\n\n{'' if markdown else '    '}{outcome}" if outcome else "")


def _example(rule: Rule, markdown: bool) -> str:
    """The example OBJ, then what ``affinity check example.obj`` prints for it."""
    output = rule.example_output.rstrip("\n")
    command = " ".join(["affinity check", *rule.example_flags, "example.obj"])
    if markdown:
        printed = f"`{command}` prints:\n\n```\n{output}\n```"
    else:
        printed = f"{command} prints:\n\n" + textwrap.indent(output, "        ")
    return _file(rule.example, printed if output else "", markdown)


def _use_instead(rule: Rule, markdown: bool) -> str:
    """The example fixed the way the page's *How to fix* says: ``affinity check`` finds it clean."""
    command = " ".join(["affinity check", *rule.example_flags, "example.obj"])
    command = f"`{command}`" if markdown else command
    return _file(rule.use_instead, f"{command} finds nothing in it (exit 0).", markdown)


#: Sections written as files, each by its own writer; the others are prose.
FILES = {"Example": _example, "Use instead": _use_instead}


def rule_page(rule: Rule, markdown: bool = False) -> str:
    """The rule's documentation page: title, summary, level and threshold, then :data:`SECTIONS`.

    Plain text for ``affinity rule``, Markdown for SARIF ``help.markdown``.
    Sections a rule leaves empty (References on Q205) are left out.
    """
    facts = f"Level: {level_text(rule)}"
    if rule.visible_threshold is not None:
        facts += f", where it is plainly visible (setting levels.{rule.code} = {{error = {rule.visible_threshold:g}}})"
    facts += "."
    if threshold_text(rule):
        facts += f" Default threshold: {threshold_text(rule)} (setting thresholds.{rule.code})."
    sections = [(title, getattr(rule, attr)) for title, attr in SECTIONS if getattr(rule, attr)]
    if markdown:
        head = [f"## {rule.code} {rule.name}", "", f"*{rule.summary}*", "", facts]
        body = [part for title, text in sections
                for part in ("", f"### {title}", "", FILES[title](rule, True) if title in FILES else text)]
    else:
        head = [f"{rule.code} {rule.name}: {rule.summary}", facts]
        fill = lambda text: textwrap.fill(text, 79, initial_indent="    ", subsequent_indent="    ")
        body = [part for title, text in sections
                for part in ("", title, FILES[title](rule, False) if title in FILES else fill(text))]
    return "\n".join(head + body) + "\n"


def rules_table() -> str:
    """The Markdown rule table of the README (generated, never edited by hand): every rule, then Q901."""
    rows = [
        "`affinity rules` lists the rules; `affinity rule CODE` prints a rule's page: what it does, why it "
        "matters, an example and what it prints, the example fixed (*Use instead*, which lints clean) and how to fix it.",
        "",
        "| Code | Name | Level | Default threshold | Flags | How to fix |",
        "|---|---|---|---|---|---|",
    ]
    for rule in (*RULES.values(), UNREADABLE):
        rows.append(
            f"| {rule.code} | `{rule.name}` | {level_text(rule)} | {threshold_text(rule) or '-'} "
            f"| {rule.summary} | {rule.fix} |"
        )
    return "\n".join(rows) + "\n"
