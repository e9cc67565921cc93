"""Running `affinity` on small OBJ files written into a test's folder: in this process (:func:`run`, the
default) or as a user does, in a process of its own (:func:`run_process`, for the tests of that boundary:
signals, start-up, worker processes, Dask, the console script).

:func:`run` gives what :func:`run_process` gives for the same arguments (exit code, stdout, stderr as
text) at a fraction of the cost (about 0.7 s of interpreter start-up and imports a call): it calls
:func:`affinity.cli.main` with file descriptors 1 and 2 pointed at temporary files, so what the
command writes there from C (USD's diagnostics), through ``sys.stdout.buffer`` or ``-o /dev/stdout``,
or from a forked worker, is captured as a pipe would capture it. What a fresh interpreter would not
carry over from the test is reset for the call and restored after it: the working folder, the
environment, the warning filters (a fresh interpreter's, shown on stderr), ``sys.stdin`` (empty), the
functools caches of ``affinity`` and ``render``. An uncaught exception ends the call as it ends a
process: its traceback on stderr and exit code 1.
"""

from __future__ import annotations

import contextlib
import functools
import io
import locale
import os
import subprocess
import sys
import threading
import traceback
import warnings
from pathlib import Path

SQUARE = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"


TRAPEZOID = "v -1 0 0\nv 1 0 0\nv 0.5 1 0\nv -0.5 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"

#: The warning filters of an interpreter started without -W or PYTHONWARNINGS (``python -m affinity.cli``).
FRESH_WARNING_FILTERS = (("default", DeprecationWarning, "__main__"), ("ignore", DeprecationWarning, ""),
                         ("ignore", PendingDeprecationWarning, ""), ("ignore", ImportWarning, ""),
                         ("ignore", ResourceWarning, ""))

#: One in-process run at a time: the working folder, the environment and file descriptors 1 and 2 are the
#: process's.
_ONE_AT_A_TIME = threading.Lock()


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``affinity ARGS`` run in this process from ``cwd``: its exit code and its stdout and stderr as text,
    as :func:`run_process` gives them (arguments may be paths or bytes, as a process's may)."""
    from affinity.cli import main

    argv = [os.fsdecode(arg) for arg in args]  # what the process's sys.argv would hold
    with _ONE_AT_A_TIME, _fresh_process_state(cwd), _captured_output() as output:
        returncode = _exit_code(main, argv)
    return subprocess.CompletedProcess([sys.executable, "-m", "affinity.cli", *args], returncode,
                                       _as_text(output["stdout"]), _as_text(output["stderr"]))


def run_process(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``affinity ARGS`` in a process of its own (``python -m affinity.cli``), as a user runs it."""
    return subprocess.run(
        [sys.executable, "-m", "affinity.cli", *args],
        capture_output=True, text=True, cwd=cwd, timeout=300,
    )


def run_without(module: str, *args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``affinity ARGS`` in a process where ``module`` cannot be imported (an extra not installed)."""
    script = (f"import sys; sys.modules[{module!r}] = None\n"
              "from affinity.cli import main\n"
              f"sys.exit(main({list(args)!r}))\n")
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=cwd, check=False)


def write(tmp_path: Path, name: str, text: str | bytes) -> Path:
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    return path


def _exit_code(main, argv: list[str]) -> int:
    """What the process running ``sys.exit(main(argv))`` would exit with; an uncaught exception's traceback
    goes to stderr as the interpreter prints it."""
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    except Exception:
        traceback.print_exc(file=sys.stderr)
        return 1
    if code is None or isinstance(code, int):
        return code or 0
    print(code, file=sys.stderr)  # sys.exit("message")
    return 1


@contextlib.contextmanager
def _fresh_process_state(cwd: Path | None):
    """The working folder ``cwd``, and for the call: a fresh interpreter's warnings, an empty stdin, empty
    ``affinity`` caches; the environment and all of these put back after it."""
    folder, environment, stdin = os.getcwd(), dict(os.environ), sys.stdin
    if cwd is not None:
        os.chdir(cwd)
    try:
        with warnings.catch_warnings():
            warnings.resetwarnings()
            for action, category, module in reversed(FRESH_WARNING_FILTERS):
                warnings.filterwarnings(action, category=category, module=module)
            warnings.showwarning = _show_warning  # pytest's catch_warnings would keep them from stderr
            sys.stdin = io.TextIOWrapper(io.BytesIO())
            _clear_caches()
            yield
    finally:
        sys.stdin = stdin
        os.environ.clear()
        os.environ.update(environment)
        os.chdir(folder)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """The interpreter's own way to print a warning: to stderr."""
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


def _clear_caches() -> None:
    """Empty the ``functools`` caches of every loaded ``affinity`` and ``render`` module, as a new process
    starts with them empty."""
    for name, module in list(sys.modules.items()):
        if module is None or name.split(".")[0] not in ("affinity", "render"):
            continue
        for value in list(vars(module).values()):
            if isinstance(value, functools._lru_cache_wrapper) and getattr(value, "__module__", None) == name:
                value.cache_clear()


@contextlib.contextmanager
def _captured_output():
    """File descriptors 1 and 2 and ``sys.stdout``/``sys.stderr`` on pipes, as ``subprocess.run`` gives a
    process (not a terminal, not a file: ``-o /dev/stdout`` is a pipe), written as a process's own streams
    are (the interpreter's encoding and error handlers); yields a dict that holds each stream's bytes
    afterwards. A thread drains each pipe, so a long output does not block."""
    output: dict[str, bytes] = {}
    streams = sys.stdout, sys.stderr
    for stream in (sys.__stdout__, sys.__stderr__):
        with contextlib.suppress(AttributeError, ValueError, OSError):
            stream.flush()
    saved = {1: os.dup(1), 2: os.dup(2)}
    readers = []
    for fd, name in ((1, "stdout"), (2, "stderr")):
        read_end, write_end = os.pipe()
        os.dup2(write_end, fd)
        os.close(write_end)
        readers.append(threading.Thread(target=_drain, args=(read_end, output, name), daemon=True))
        readers[-1].start()
    try:
        sys.stdout, sys.stderr = _stream(1, sys.__stdout__), _stream(2, sys.__stderr__)
        try:
            yield output
        finally:
            for stream in (sys.stdout, sys.stderr):
                with contextlib.suppress(ValueError, OSError):  # closed by the command (a broken pipe)
                    stream.flush()
    finally:
        sys.stdout, sys.stderr = streams
        for fd, copy in saved.items():
            os.dup2(copy, fd)  # closes the pipe's last write end: its reader sees the end
            os.close(copy)
        for reader in readers:
            reader.join()


def _drain(read_end: int, output: dict[str, bytes], name: str) -> None:
    """Read the pipe ``read_end`` to its end into ``output[name]``."""
    with open(read_end, "rb") as pipe:
        output[name] = pipe.read()


def _stream(fd: int, original) -> io.TextIOWrapper:
    """A text stream on ``fd`` made as the interpreter makes its own for a pipe: the encoding and error
    handler of ``original`` (``sys.__stdout__`` or ``sys.__stderr__``, which a child inherits through
    the locale), line-buffered stderr, and no buffer at all under PYTHONUNBUFFERED."""
    unbuffered = bool(os.environ.get("PYTHONUNBUFFERED"))
    raw = io.FileIO(fd, "w", closefd=False)
    return io.TextIOWrapper(raw if unbuffered else io.BufferedWriter(raw),
                            encoding=getattr(original, "encoding", None) or locale.getpreferredencoding(False),
                            errors=getattr(original, "errors", None) or ("strict" if fd == 1 else "backslashreplace"),
                            line_buffering=fd == 2 and not unbuffered, write_through=unbuffered)


def _as_text(data: bytes) -> str:
    """Bytes as ``subprocess.run(text=True)`` decodes them: the locale's encoding, strict, universal newlines."""
    text = data.decode(locale.getpreferredencoding(False))
    return text.replace("\r\n", "\n").replace("\r", "\n")
