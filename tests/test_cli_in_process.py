"""``helpers.cli.run`` (``affinity`` in the test's process) against ``helpers.cli.run_process`` (a process of
its own, as a user runs it): the same exit code, stdout and stderr, and no defect a process would show
hidden: an uncaught exception, a warning, a write to a file descriptor, a file changed between two runs."""

from __future__ import annotations

import os
import re
import sys
import warnings

import pytest
from helpers.cli import SQUARE, TRAPEZOID, run, run_process, write

BAD_OBJ = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n"
#: A stage whose prim references a layer that is not there: USD says so on stderr from C++ as well.
BROKEN_REFERENCE = '#usda 1.0\ndef Mesh "m" (prepend references = @./missing.usda@) {}\n'

COMMANDS = {
    "clean": ["check", "square.obj"],
    "findings": ["check", "trapezoid.obj"],
    "json to -o -": ["check", "--format", "json", "-o", "-", "trapezoid.obj"],
    "sarif to /dev/stdout": ["check", "--format", "sarif", "-o", "/dev/stdout", "trapezoid.obj"],
    "bad file": ["check", "bad.obj"],
    "name not UTF-8": ["check", os.fsdecode(b"bad\xff.obj")],
    "folder": ["check", "--no-cache", "--verbose", "--statistics", "."],
    "usage error": ["check", "--no-such-option"],
    "help": ["check", "--help"],
    "version": ["--version"],
    "rule page": ["rule", "Q101"],
    "fix to -": ["fix", "--diff", "trapezoid.obj"],
    "USD reference missing": ["check", "--no-cache", "broken.usda"],  # a cached result opens no stage
}


@pytest.fixture
def folder(tmp_path):
    write(tmp_path, "square.obj", SQUARE)
    write(tmp_path, "trapezoid.obj", TRAPEZOID)
    write(tmp_path, "bad.obj", BAD_OBJ)
    (tmp_path / os.fsdecode(b"bad\xff.obj")).write_text(BAD_OBJ)
    write(tmp_path, "broken.usda", BROKEN_REFERENCE)
    return tmp_path


@pytest.mark.parametrize("args", COMMANDS.values(), ids=COMMANDS.keys())
def test_in_process_gives_what_a_process_gives(folder, args):
    if args[-1].endswith(".usda"):
        pytest.importorskip("pxr")
    here, there = run(*args, cwd=folder), run_process(*args, cwd=folder)
    assert (here.returncode, here.stdout, without_addresses(here.stderr)) == (
        there.returncode, there.stdout, without_addresses(there.stderr))


def without_addresses(text: str) -> str:
    """USD's diagnostics name the stage by its address in memory, which changes from run to run."""
    return re.sub(r"<0x[0-9a-f]+>", "<0x...>", text)


def test_the_comparison_sees_a_difference(folder):
    """The comparison above can fail: two runs that differ in one option differ in what it compares."""
    here, there = run("check", "trapezoid.obj", cwd=folder), run_process("check", "-q", "trapezoid.obj", cwd=folder)
    assert (here.returncode, here.stdout, here.stderr) != (there.returncode, there.stdout, there.stderr)


def test_a_shared_mesh_in_process_gives_what_a_process_gives(shared_meshes):
    """A real textured mesh (its MTL and PNG read): the same lines and the same exit code."""
    mesh = str(shared_meshes / "textured" / "spot_control_mesh_textured.obj")
    here, there = run("check", "--no-cache", "--format", "json", mesh), run_process("check", "--no-cache",
                                                                                  "--format", "json", mesh)
    assert (here.returncode, here.stdout, here.stderr) == (there.returncode, there.stdout, there.stderr)
    assert '"Q101"' in here.stdout


# -- what a command does that only a process would show -------------------------------------------------

#: Each a ``behaviour(args)`` put in place of ``affinity rules``; the same source runs in both.
BEHAVIOURS = {
    "raises": "def behaviour(args):\n    raise RuntimeError('boom')\n",
    "exits with a message": "import sys\ndef behaviour(args):\n    sys.exit('stopped here')\n",
    "writes every way": ("import os, sys\n"
                         "def behaviour(args):\n"
                         "    print('text')\n"
                         "    sys.stdout.buffer.write(b'bytes\\n')\n"
                         "    os.write(1, b'fd 1\\n')\n"
                         "    sys.stderr.write('stderr\\n')\n"
                         "    os.write(2, b'fd 2\\n')\n"
                         "    return 3\n"),
    "warns": ("import warnings\n"
              "def behaviour(args):\n"
              "    warnings.warn('careful', RuntimeWarning)\n"
              "    warnings.warn('old', DeprecationWarning)\n"
              "    return 0\n"),
}


def _in_process(monkeypatch, source: str):
    import affinity.commands.rules as rules_command

    namespace: dict = {"__name__": "behaviour"}
    exec(source, namespace)
    monkeypatch.setattr(rules_command, "run_rules", namespace["behaviour"])
    return run("rules")


def _in_a_process(source: str):
    import subprocess

    script = (f"namespace = {{'__name__': 'behaviour'}}\nexec({source!r}, namespace)\n"
              "import runpy, affinity.commands.rules as r\nr.run_rules = namespace['behaviour']\n"
              "runpy.run_module('affinity.cli', run_name='__main__', alter_sys=True)\n")
    return subprocess.run([sys.executable, "-c", script, "rules"], capture_output=True, text=True, timeout=120)


def test_an_uncaught_exception_is_a_traceback_and_exit_1_as_in_a_process(monkeypatch):
    here, there = _in_process(monkeypatch, BEHAVIOURS["raises"]), _in_a_process(BEHAVIOURS["raises"])
    for result in (here, there):
        assert result.returncode == 1
        assert result.stderr.startswith("Traceback (most recent call last):\n")
        assert result.stderr.endswith("RuntimeError: boom\n")


@pytest.mark.parametrize("name", ["exits with a message", "writes every way"])
def test_exits_and_writes_are_what_a_process_gives(monkeypatch, name):
    here, there = _in_process(monkeypatch, BEHAVIOURS[name]), _in_a_process(BEHAVIOURS[name])
    assert (here.returncode, here.stdout, here.stderr) == (there.returncode, there.stdout, there.stderr)
    assert here.returncode in (1, 3) and here.stderr


def test_a_warning_is_printed_on_stderr_each_run_as_in_a_process(monkeypatch):
    """A fresh interpreter prints a RuntimeWarning (not a DeprecationWarning outside __main__), once a
    process: two runs here print it twice, whatever pytest's own filters."""
    there = _in_a_process(BEHAVIOURS["warns"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # what ``-W error`` would make of a test process
        first, second = _in_process(monkeypatch, BEHAVIOURS["warns"]), _in_process(monkeypatch, BEHAVIOURS["warns"])
    for result in (there, first, second):
        assert result.returncode == 0
        assert "RuntimeWarning: careful" in result.stderr and "old" not in result.stderr


def test_the_run_leaves_the_test_process_as_it_found_it(folder, monkeypatch):
    """The working folder, the environment (``affinity`` sets BLAS variables for its process), the streams,
    the warning filters and what file descriptors 1 and 2 name."""
    for name in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        monkeypatch.delenv(name, raising=False)
    before = (os.getcwd(), dict(os.environ), sys.stdout, sys.stderr, sys.stdin, list(warnings.filters),
              [os.fstat(fd).st_ino for fd in (1, 2)])
    assert run("check", "trapezoid.obj", cwd=folder).returncode == 1
    after = (os.getcwd(), dict(os.environ), sys.stdout, sys.stderr, sys.stdin, list(warnings.filters),
             [os.fstat(fd).st_ino for fd in (1, 2)])
    assert after == before


def test_the_run_sets_the_environment_a_process_of_affinity_has(folder, monkeypatch):
    """It is the command that sets OPENBLAS_NUM_THREADS, seen by what it starts: the run does not skip it."""
    for name in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        monkeypatch.delenv(name, raising=False)
    import affinity.commands.rules as rules_command

    monkeypatch.setattr(rules_command, "run_rules", lambda args: print(os.environ.get("OPENBLAS_NUM_THREADS")))
    assert run("rules").stdout == "1\n"


def test_each_run_starts_with_empty_caches(folder):
    """As a new process does: a cache of what a file held cannot answer for a file changed since."""
    from affinity.draw.texture import checker

    checker(64)
    assert checker.cache_info().currsize >= 1
    run("check", "square.obj", cwd=folder)
    assert checker.cache_info().currsize == 0


def test_a_stage_rewritten_between_two_runs_is_read_afresh(folder):
    """USD keeps layers it has open by identifier: a second run must see the stage as the file now is."""
    pytest.importorskip("pxr")
    from helpers.usd_stages import flagged_stage

    stage = flagged_stage(folder, "stage.usda")
    flagged = run("check", "--no-cache", "stage.usda", cwd=folder)
    stage.write_text("#usda 1.0\n")
    emptied = run("check", "--no-cache", "stage.usda", cwd=folder)
    fresh = run_process("check", "--no-cache", "stage.usda", cwd=folder)
    assert flagged.returncode == 1 and "Q101" in flagged.stdout
    assert (emptied.returncode, emptied.stdout, emptied.stderr) == (fresh.returncode, fresh.stdout, fresh.stderr)
    assert "Q101" not in emptied.stdout
