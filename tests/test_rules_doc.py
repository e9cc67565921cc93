"""Rule documentation: one source (affinity/rules.py) for ``affinity rule``, SARIF help and the README."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from helpers.cli import run

from affinity.rules import RULES, SECTIONS, UNREADABLE, rule_page, rules_table

README = Path(__file__).resolve().parents[1] / "README.md"


def test_rule_page_has_the_four_sections_in_order_and_the_crease():
    result = run("rule", "Q101")
    assert result.returncode == 0, result.stderr
    page = result.stdout
    assert page.startswith("Q101 uv-disaffine: texture coordinates are not an affine image of the positions\n")
    positions = [page.index(f"\n{title}\n") for title in ["What it does", "Why it matters", "Example", "How to fix"]]
    assert positions == sorted(positions)
    why = page[positions[1]:positions[2]]
    assert "diagonal" in why and "crease" in why
    assert "0.5 texels" in page


def test_rule_page_accepts_names_and_any_case():
    by_name, by_code = run("rule", "uv-disaffine"), run("rule", "q101")
    assert by_name.returncode == by_code.returncode == 0
    assert by_name.stdout == by_code.stdout == rule_page(RULES["Q101"])
    assert by_code.stdout.startswith("Q101 uv-disaffine: ") and "How to fix" in by_code.stdout


def test_unknown_rule_is_a_usage_error():
    result = run("rule", "Q999")
    assert result.returncode == 2 and "Q999" in result.stderr and "Traceback" not in result.stderr


def test_rules_lists_every_code_once():
    result = run("rules")
    assert result.returncode == 0
    codes = [line.split()[0] for line in result.stdout.splitlines()]
    assert codes == [*RULES, UNREADABLE.code]


@pytest.mark.parametrize("code", [*RULES, UNREADABLE.code])
def test_every_rule_is_documented_and_ends_with_a_fix(code):
    rule = RULES.get(code, UNREADABLE)
    assert re.fullmatch(r"Q\d{3}", rule.code) and re.fullmatch(r"[a-z]+(-[a-z]+)*", rule.name)
    for _, attr in SECTIONS:
        assert len(getattr(rule, attr)) > 20, (code, attr)
    assert rule_page(rule, markdown=True).rstrip().endswith("### How to fix\n\n" + rule.fix)


def test_readme_rule_table_is_the_generated_one():
    text = README.read_text()
    match = re.search(r"<!-- rules:start -->\n(.*?)<!-- rules:end -->", text, re.S)
    assert match, "README.md lacks the <!-- rules:start --> / <!-- rules:end --> markers"
    assert match[1] == rules_table(), "regenerate the table with `affinity rules --markdown`"
    assert run("rules", "--markdown").stdout == rules_table()


def test_the_affinity_fixes_say_what_removes_the_crease_and_speak_of_their_attribute():
    """Design.md: refining or re-UVing removes a crease; triangulating only makes every tool draw the same one."""
    uv = RULES["Q101"].fix
    assert "Refine the quad" in uv and "affinity fix" in uv and "re-UV it as a parallelogram" in uv
    assert "Triangulating does not remove the crease" in uv
    for code, attribute in (("Q102", "colour"), ("Q103", "normal")):
        fix = RULES[code].fix
        assert attribute in fix and "Refine the quad" in fix and "does not remove" in fix
        assert "uv" not in fix.lower() and "unwrap" not in fix.lower()
