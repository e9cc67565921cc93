"""The Q901 line is written in one place (issue 51): every command says an unreadable file the same way, its
name escaped (an ESC byte in a file name never reaches the terminal raw)."""

from __future__ import annotations

from helpers.cli import run, write


def test_check_and_fix_say_an_unreadable_file_alike_and_escaped(tmp_path):
    path = write(tmp_path, "bad\x1b[31m.obj", "v 0 0 0\nf 1 2 3 4\n")  # vertex 2 does not exist (line 2)
    checked = run("check", "--no-cache", path.name, cwd=tmp_path)
    fixed = run("fix", "--dry-run", path.name, cwd=tmp_path)
    assert checked.returncode == fixed.returncode == 2
    [line] = [line for line in checked.stderr.splitlines() if " Q901 " in line]
    assert line.startswith('"bad\\x1b[31m.obj":2: Q901 unreadable: '), line
    assert "\x1b" not in checked.stderr and "\x1b" not in fixed.stderr
    assert line in fixed.stderr.splitlines()
