"""The rule registry is the one place a rule lives: its example triggers it alone, and a rule
registered at run time reaches lint, `affinity rules`, SARIF and the README table."""

from __future__ import annotations

import json

import numpy as np
import pytest

from affinity import cli
from affinity.lint import lint_mesh
from affinity.loaders import load
from affinity.rules import RULES, Measured, Rule, register, rules_table, unregister
from affinity.settings import Settings


def check(args: list[str], capsys) -> tuple[int, str, str]:
    code = cli.main(args)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("code", list(RULES))
def test_each_rules_example_triggers_that_rule_and_only_it(code, tmp_path, monkeypatch, capsys):
    rule = RULES[code]
    # two faces at least where the rule needs a neighbour (Q106: subdivision's smooth rules)
    assert 4 <= len(rule.example.splitlines()) <= (16 if rule.example_flags else 10), "the example is a tiny OBJ"
    (tmp_path / "example.obj").write_text(rule.example)
    monkeypatch.chdir(tmp_path)
    status, out, err = check(["check", "--select", "ALL", "--fail-on", "info", "--format", "json",
                              *rule.example_flags, "example.obj"], capsys)
    assert status == 1, err
    findings = json.loads(out)["findings"]
    assert {f["code"] for f in findings} == {code}
    visible = rule.visible_threshold
    expected = {"error" if visible is not None and f["value"] > visible else rule.level for f in findings}
    assert {f["level"] for f in findings} == expected and {f["unit"] for f in findings} == {rule.unit}
    status, out, _ = check(["check", "--select", "ALL", *rule.example_flags, "example.obj"], capsys)
    lines = [line for line in out.splitlines() if not line.startswith("Found ")]
    assert rule.example_output, f"{code}: the page shows what affinity check prints for its example"
    assert "\n".join(lines) + "\n" == rule.example_output


def count_corners(quads) -> Measured:
    """A synthetic measure: the number of corners of every quad (always 4)."""
    return Measured(slice(None), np.full(len(quads), 4.0))


@pytest.fixture
def synthetic_rule():
    rule = register(Rule(
        code="Q999", name="synthetic-rule", summary="a rule registered by a test", unit="corners",
        default_threshold=3.0, check=count_corners, family="QuadShape",
        what="Counts corners.", why="To show that the registry is the only place a rule lives.",
        example="v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", fix="Unregister it.",
    ))
    yield rule
    unregister(rule.code)


def test_a_rule_registered_at_run_time_is_everywhere(synthetic_rule, tmp_path, monkeypatch, capsys):
    (tmp_path / "square.obj").write_text(synthetic_rule.example)
    mesh = load(str(tmp_path / "square.obj"))
    hits = {h.code: h for h in lint_mesh(mesh, Settings(select=["Q999"]))}
    assert list(hits) == ["Q999"] and hits["Q999"].values.tolist() == [4.0]

    status, out, _ = check(["rules"], capsys)
    assert status == 0 and "Q999  synthetic-rule" in out
    status, out, _ = check(["rule", "Q999"], capsys)
    assert status == 0 and out.startswith("Q999 synthetic-rule: a rule registered by a test\n")
    assert "| Q999 | `synthetic-rule` | warning | 3 corners |" in rules_table()

    monkeypatch.chdir(tmp_path)
    status, out, _ = check(["check", "--select", "Q999", "--fail-on", "warning", "--format", "sarif", "square.obj"],
                           capsys)
    sarif = json.loads(out)
    driver_rules = sarif["runs"][0]["tool"]["driver"]["rules"]
    assert "Q999" in [r["id"] for r in driver_rules]
    result, = sarif["runs"][0]["results"]
    assert driver_rules[result["ruleIndex"]]["id"] == "Q999" and status == 1


def test_a_code_registers_once(synthetic_rule):
    with pytest.raises(ValueError, match="Q999"):
        register(synthetic_rule)


def test_the_registry_shows_how_to_add_a_rule_with_code_that_works(tmp_path, monkeypatch, capsys):
    """The module docstring of affinity/rules/registry.py, run as it is, registers a rule whose page's
    example (a 2 by 1 rectangle: longest edge 2, closed form) prints the page's Prints line and whose
    Use instead lints clean."""
    import textwrap

    from affinity.rules import registry

    source = textwrap.dedent(registry.__doc__.split("::\n", 1)[1].split("\nCodes never change")[0])
    namespace: dict = {}
    exec(compile(source, "affinity/rules/registry.py docstring", "exec"), namespace)
    try:
        rule = RULES["Q999"]
        assert rule.check is namespace["long_edge"] and rule.name == "long-edge"
        (tmp_path / "example.obj").write_text(rule.example)
        monkeypatch.chdir(tmp_path)
        status, out, err = check(["check", "--select", "Q999", "--fail-on", "warning", "example.obj"], capsys)
        assert status == 1, err
        assert [line for line in out.splitlines() if not line.startswith("Found ")] == rule.example_output.splitlines()
        assert "(2 vs 1 units)" in rule.example_output
        (tmp_path / "fixed.obj").write_text(rule.use_instead)  # two unit squares: no edge above 1
        status, out, err = check(["check", "--select", "Q999", "--fail-on", "info", "fixed.obj"], capsys)
        assert status == 0 and "Q999" not in out, out + err
    finally:
        unregister("Q999")
    assert "Q999" not in RULES
