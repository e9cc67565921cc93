"""``affinity rules`` lists every rule; ``affinity rule CODE`` prints one rule's page.

The text comes from :mod:`affinity.rules`, the same source as SARIF help and the
README's rule table (``affinity rules --markdown`` prints that table).
"""

from __future__ import annotations

import sys

from ..errors import UsageError
from . import EXIT_CLEAN


def add_parser(sub) -> None:
    from ..rules import RULES

    listing = sub.add_parser("rules", help="list every rule", description="List every rule code, name and summary.")
    listing.add_argument("--markdown", action="store_true", help="print the README's Markdown rule table")
    listing.set_defaults(run=run_rules)
    page = sub.add_parser(
        "rule", help="explain one rule",
        description="Print what a rule detects, why it matters, an example and how to fix it.",
    )
    first = next(iter(RULES.values()))
    page.add_argument("code", metavar="CODE", help=f"rule code or name, e.g. {first.code} or {first.name}")
    page.set_defaults(run=run_rule)


def run_rules(args) -> int:
    from ..rules import RULES, UNREADABLE, rules_table, threshold_text

    if args.markdown:
        sys.stdout.write(rules_table())
        return EXIT_CLEAN
    for rule in (*RULES.values(), UNREADABLE):
        threshold = threshold_text(rule) or "-"
        sys.stdout.write(f"{rule.code}  {rule.name:<17} {rule.level:<8} {threshold:<20} {rule.summary}\n")
    return EXIT_CLEAN


def run_rule(args) -> int:
    from ..rules import find_rule, rule_page

    rule = find_rule(args.code)
    if rule is None:
        raise UsageError(f"unknown rule {args.code!r} (see affinity rules)")
    sys.stdout.write(rule_page(rule))
    return EXIT_CLEAN
