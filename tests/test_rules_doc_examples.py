"""Both halves of every rule page, as ruff keeps them: the *Example* that triggers the rule and the
*Use instead* that fixes it the way *How to fix* says. Each is linted by ``affinity check`` run as a user
runs it (``helpers.cli.run``, every rule selected) in a folder holding that one file.

The example's printed lines of Q101-Q902 are compared in ``test_rule_registry.py``; Q901 (not a lint rule,
its line goes to stderr) is compared here.
"""

from __future__ import annotations

import json

import pytest
from helpers.cli import run

from affinity.rules import RULES, UNREADABLE, rule_page

PAGES = {**RULES, UNREADABLE.code: UNREADABLE}


def lint(tmp_path, text: str, *options: str):
    """``affinity check --select ALL --fail-on info`` on ``text`` saved as ``example.obj``."""
    (tmp_path / "example.obj").write_text(text)
    return run("check", "--select", "ALL", "--fail-on", "info", *options, "example.obj", cwd=tmp_path)


@pytest.mark.parametrize("code", PAGES)
def test_use_instead_lints_clean(code, tmp_path):
    rule = PAGES[code]
    lines = rule.use_instead.splitlines()
    assert 4 <= len(lines) <= (16 if rule.example_flags else 10) and lines[0].startswith("# "), \
        "a tiny OBJ that says what it changed"
    assert rule.use_instead != rule.example
    result = lint(tmp_path, rule.use_instead, "--format", "json", *rule.example_flags)
    assert result.returncode == 0, result.stdout + result.stderr
    report = json.loads(result.stdout)
    assert report["findings"] == [] and report["summary"]["checked"] == 1
    file, = report["files"]
    assert "error" not in file and "skipped" not in file and file["faces"] >= 1


@pytest.mark.parametrize("code", PAGES)
def test_use_instead_changes_what_the_fix_names_and_keeps_the_rest(code):
    """The fixed file keeps the example's kind of data (a uv fix keeps uv, a colour fix colours) and
    changes some of it: it is the example repaired, not an unrelated clean mesh."""
    rule = PAGES[code]
    kinds = lambda text: {line.split()[0] for line in text.splitlines() if line.strip() and line[0] != "#"}
    assert {"v", "f"} <= kinds(rule.use_instead)
    assert kinds(rule.example) - {"mtllib"} <= kinds(rule.use_instead) | {"f"}
    carries = {"texcoords": lambda w: w[0] == "vt", "normals": lambda w: w[0] == "vn",
               "colors": lambda w: w[0] == "v" and len(w) == 7}
    if rule.attribute:
        assert any(carries[rule.attribute](line.split()) for line in rule.use_instead.splitlines() if line.strip())


def test_unreadable_example_prints_its_line_and_exits_2(tmp_path):
    result = lint(tmp_path, UNREADABLE.example)
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert UNREADABLE.example_output, "the page shows what affinity check prints for its example"
    assert result.stderr == UNREADABLE.example_output


@pytest.mark.parametrize("code", PAGES)
def test_pages_show_use_instead_after_the_example(code):
    page = run("rule", code).stdout
    plain = [page.index(f"\n{title}\n") for title in ("Example", "Use instead", "How to fix")]
    assert plain == sorted(plain)
    command = " ".join(["affinity check", *PAGES[code].example_flags, "example.obj"])
    assert f"{command} finds nothing in it (exit 0)." in page[plain[1]:plain[2]]
    first_line = PAGES[code].use_instead.splitlines()[0]
    assert f"\n        {first_line}\n" in page[plain[1]:plain[2]]
    block = f"### Use instead\n\n```\n{PAGES[code].use_instead}```\n\n`{command}` finds nothing"
    assert block in rule_page(PAGES[code], markdown=True)


def test_sarif_help_carries_use_instead(tmp_path):
    (tmp_path / "example.obj").write_text(RULES["Q101"].example)
    result = run("check", "--format", "sarif", "example.obj", cwd=tmp_path)
    rules = {r["id"]: r for r in json.loads(result.stdout)["runs"][0]["tool"]["driver"]["rules"]}
    for code, rule in rules.items():
        assert "### Use instead" in rule["help"]["markdown"] and "\nUse instead\n" in rule["help"]["text"], code
        assert PAGES[code].use_instead.splitlines()[1] in rule["help"]["markdown"]


def test_missing_resource_is_also_fixed_by_shipping_the_library(tmp_path):
    """Q902's first fix needs a second file, so its *Use instead* shows the third (no library line); the
    first one is checked here: the example unchanged, with the library it names beside it."""
    (tmp_path / "missing.mtl").write_text("newmtl grey\nKd 0.5 0.5 0.5\n")
    result = lint(tmp_path, RULES["Q902"].example)
    assert result.returncode == 0 and "No findings" in result.stdout, result.stdout + result.stderr
    (tmp_path / "missing.mtl").unlink()
    assert lint(tmp_path, RULES["Q902"].example).returncode == 1
