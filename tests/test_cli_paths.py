"""File names on the command line and in human output (issue 47): control characters are shown, never
sent; one file reached by several spellings is checked once; ``-o -`` is standard output and
``--show-settings`` honours ``-o``."""

from __future__ import annotations

import ast
import json
import os
from pathlib import Path

from helpers.cli import SQUARE, TRAPEZOID, run
from hypothesis import given
from hypothesis import strategies as st

from affinity.output.names import printable

#: Names a user may really meet: a newline, a colour escape, a carriage return, a bidi override, a tab.
HOSTILE = ["two\nlines.obj", "\x1b[31mred\x1b[0m.obj", "back\rspace.obj", "evil\u202egnp.obj", "tab\there.obj"]


def unescaped(name: str) -> str:
    """What Python's own literal parser reads from ``printable``'s quoted form: the name, with each byte
    that is not UTF-8 (a surrogate escape) read as the character of that code point."""
    return "".join(chr(ord(c) - 0xDC00) if 0xDC80 <= ord(c) <= 0xDCFF else c for c in name)


@given(st.text(st.characters(codec="utf-8") | st.sampled_from([chr(0xDC80 + k) for k in range(128)])))
def test_printable_names_print_and_read_back_as_python_literals(name):
    shown = printable(name)
    assert shown.isprintable()
    if name.isprintable():
        assert shown == name
    else:
        assert ast.literal_eval(shown) == unescaped(name)


def test_control_characters_in_names_are_shown_not_sent(tmp_path):
    for name in HOSTILE:
        (tmp_path / name).write_text(TRAPEZOID)
    (tmp_path / "broken\x1b[2J.obj").write_text("v 0 0 0\nf 1 2 9\n")
    (tmp_path / os.fsdecode(b"caf\xe9.obj")).write_text(TRAPEZOID)  # not UTF-8
    done = run("check", ".", cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    for stream in (done.stdout, done.stderr):
        assert stream.isascii() or all(c.isprintable() for c in stream.replace("\n", ""))
        assert "\x1b" not in stream and "\r" not in stream and "\u202e" not in stream
    findings = done.stdout.splitlines()[:-1]
    assert len(findings) == len(HOSTILE) + 1 and all(" Q101 " in line for line in findings)
    for name in HOSTILE:
        assert sum(line.startswith(printable(name) + ":9:1: Q101") for line in findings) == 1
    assert any(line.startswith('"caf\\xe9.obj":9:1: Q101') for line in findings)
    assert done.stderr.startswith('"broken\\x1b[2J.obj":2: Q901 unreadable')
    listed = run("check", "--show-files", ".", cwd=tmp_path)
    assert len(listed.stdout.splitlines()) == len(HOSTILE) + 2 and "\x1b" not in listed.stdout
    json_run = run("check", "--format", "json", ".", cwd=tmp_path)  # machine formats keep the name exact
    assert {Path(entry["path"]).name for entry in json.loads(json_run.stdout)["files"]} >= set(HOSTILE)


def test_one_file_under_four_spellings_is_checked_once_under_the_first(tmp_path):
    (tmp_path / "mesh.obj").write_text(TRAPEZOID)
    (tmp_path / "link.obj").symlink_to("mesh.obj")
    spellings = ["mesh.obj", str(tmp_path / "mesh.obj"), "./mesh.obj", "link.obj"]
    done = run("check", "--format", "json", *spellings, cwd=tmp_path)
    assert [entry["path"] for entry in json.loads(done.stdout)["files"]] == ["mesh.obj"]
    assert [f["path"] for f in json.loads(done.stdout)["findings"]] == ["mesh.obj"]
    reversed_order = run("check", *spellings[::-1], cwd=tmp_path)
    assert [line.split(":")[0] for line in reversed_order.stdout.splitlines()[:-1]] == ["link.obj"]
    assert "1 file checked" in reversed_order.stdout
    twice = run("check", "--show-files", ".", "./", str(tmp_path), cwd=tmp_path)
    assert twice.stdout.splitlines() == ["link.obj"]  # the walk's first name for the file: sorted, link first


def test_dash_output_is_standard_output(tmp_path):
    (tmp_path / "mesh.obj").write_text(TRAPEZOID)
    plain = run("check", "--format", "json", "mesh.obj", cwd=tmp_path)
    dashed = run("check", "--format", "json", "-o", "-", "mesh.obj", cwd=tmp_path)
    assert (dashed.returncode, dashed.stdout) == (plain.returncode, plain.stdout) == (1, plain.stdout)
    assert sorted(os.listdir(tmp_path)) == ["mesh.obj"]  # no file named '-'
    named = run("check", "--format", "json", "-o", "./-", "mesh.obj", cwd=tmp_path)
    assert named.stdout == "" and (tmp_path / "-").read_text() == plain.stdout


def test_show_settings_writes_the_output_file(tmp_path):
    (tmp_path / "mesh.obj").write_text(SQUARE)
    (tmp_path / "affinity.toml").write_text("texture-size = 512\n")
    printed = run("check", "--show-settings", "mesh.obj", cwd=tmp_path)
    written = run("check", "--show-settings", "-o", "settings.toml", "mesh.obj", cwd=tmp_path)
    assert printed.returncode == written.returncode == 0
    assert written.stdout == "" and (tmp_path / "settings.toml").read_text() == printed.stdout
    assert "texture-size = 512" in printed.stdout
