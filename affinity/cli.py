"""The ``affinity`` command line.

Exit codes (design.md): 0 nothing flagged, 1 findings, 2 usage error or
unreadable input (2 wins over 1). Findings go to stdout, errors to stderr.
"""

from __future__ import annotations

import argparse
import functools
import sys

from .commands import EXIT_CLEAN, EXIT_ERROR
from .commands import bench as bench_command
from .commands import check as check_command
from .commands import fix as fix_command
from .commands import merge as merge_command
from .commands import render as render_command
from .commands import report as report_command
from .commands import rules as rules_command
from .commands import stability as stability_command
from .commands import usd_plugin as usd_plugin_command
from .commands import view as view_command
from .errors import UsageError

SUBCOMMANDS = [check_command, fix_command, merge_command, render_command, rules_command, report_command,
               view_command, stability_command, bench_command, usd_plugin_command]
# The subcommand names each module adds; all of them are set up only when the arguments name none.
COMMAND_NAMES = {"check": check_command, "fix": fix_command, "merge": merge_command, "render": render_command,
                 "rules": rules_command, "rule": rules_command, "report": report_command, "view": view_command,
                 "stability": stability_command, "bench": bench_command, "usd-plugin": usd_plugin_command}


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The ``affinity`` parser. When ``argv`` (default ``sys.argv[1:]``) starts with a subcommand, only
    that one gets its options (the others are bare names, still valid choices): setting up every
    subcommand's options, and importing what their choices list, is a good share of a pre-commit
    hook's start-up."""
    from . import __version__

    # No prefix matching anywhere: '--stat' is not '--statistics', and '--fail-on error' never
    # parses as '--fail-on-skip' plus a path named 'error'.
    parser = argparse.ArgumentParser(
        prog="affinity",
        description="Lint quad meshes for texture/colour affinity and render them with a hybrid rasterizer.",
        allow_abbrev=False,
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                parser_class=functools.partial(argparse.ArgumentParser, allow_abbrev=False))
    args = sys.argv[1:] if argv is None else argv
    chosen = COMMAND_NAMES.get(args[0]) if args else None
    for command in SUBCOMMANDS if chosen is None else [chosen]:
        command.add_parser(sub)
    for name in COMMAND_NAMES:
        if name not in sub.choices:
            sub.add_parser(name)
    return parser


def main(argv: list[str] | None = None) -> int:
    from .commands.allocator import keep_freed_memory, one_blas_thread

    one_blas_thread()
    args = build_parser(argv).parse_args(argv)
    keep_freed_memory()
    try:
        return args.run(args)
    except UsageError as err:
        sys.stderr.write(f"affinity {args.command}: error: {err}\n")
        return EXIT_ERROR
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        sys.stderr.close()
        return EXIT_CLEAN


def console_main() -> int:
    """The ``affinity`` program: :func:`main` in a process of its own.

    Before the interpreter exits, every object is moved out of the garbage
    collector's reach (``gc.freeze``): the exit then frees them without the
    collections the teardown of pyvista's and matplotlib's modules set off
    (measured after a report: 0.50 s of exit, 0.07 s frozen).
    """
    import gc

    _unwind_on_sigterm()
    code = main()
    gc.freeze()
    return code


def _unwind_on_sigterm() -> None:
    """SIGTERM ends the program as an exception does: ``finally`` blocks run, so a half-written output's
    temporary file is removed and the ``--jobs`` workers are stopped; a second SIGTERM ends it at once."""
    import signal

    def terminated(signum, frame):
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, terminated)


if __name__ == "__main__":
    sys.exit(console_main())
