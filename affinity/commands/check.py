"""``affinity check PATH...``: lint mesh files (see design.md for output and exit codes)."""

from __future__ import annotations

import argparse
import sys

from ..check import UsageError
from . import EXIT_CLEAN, EXIT_ERROR, EXIT_FINDINGS


def _codes(text: str) -> list[str]:
    return [c.strip().upper() for c in text.split(",") if c.strip()]


def _threshold(text: str) -> tuple[str, float]:
    """``0.8`` (the uv rule Q101) or ``CODE=VALUE``."""
    code, _, value = text.rpartition("=")
    try:
        return (code.strip().upper() or "Q101"), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a threshold: {text!r} (use 0.8 or Q102=3)") from None


def add_parser(sub) -> None:
    p = sub.add_parser(
        "check", help="lint mesh files for quad affinity and shape problems",
        description="Lint .obj/.ply/.off files (directories are searched recursively).",
    )
    p.add_argument("paths", nargs="*", metavar="PATH")
    p.add_argument("--demo", action="store_true", help="also check the bundled demo meshes")
    p.add_argument("--format", choices=["text", "json"], default="text")
    p.add_argument("--select", type=_codes, help="rule codes or prefixes to enable, e.g. Q1,Q201")
    p.add_argument("--ignore", type=_codes, help="rule codes or prefixes to disable")
    p.add_argument(
        "--threshold", type=_threshold, action="append", default=[], metavar="[CODE=]VALUE",
        help="flag above VALUE: a bare number sets Q101 (uv); repeat CODE=VALUE for other rules",
    )
    p.add_argument(
        "--measure", choices=["misplacement", "barycentric"], default="misplacement",
        help="Q101 reading: misplacement in texels (default) or the paper's barycentric score",
    )
    p.add_argument("--diagonal", choices=["both", "02", "13", "shortest"], default="both",
                   help="which split diagonal the affinity test measures (default: both)")
    p.add_argument("--texture-size", type=int, default=1024, metavar="PX",
                   help="texture size for texel units when the mesh names no readable map_Kd")
    p.add_argument("--statistics", action="store_true", help="print counts per rule instead of findings")
    p.add_argument("--verbose", action="store_true", help="show every finding in text output")
    p.add_argument("-q", "--quiet", action="store_true", help="print findings and nothing else")
    p.set_defaults(run=run)


def _settings(args):
    from ..rules import RULES
    from ..settings import Settings

    thresholds = dict(args.threshold)
    unknown = sorted(set(thresholds) - set(RULES))
    if unknown:
        raise UsageError(f"--threshold: unknown rule {', '.join(unknown)}")
    if args.texture_size <= 0:
        raise UsageError("--texture-size must be a positive number of pixels")
    return Settings(
        select=args.select, ignore=args.ignore, thresholds=thresholds,
        measure=args.measure, diagonal=args.diagonal, texture_size=args.texture_size,
    )


def run(args) -> int:
    from ..check import check_paths, collect_paths
    from ..output import text

    settings = _settings(args)
    paths = list(args.paths)
    if args.demo:
        from ..scenes import demo_paths

        paths += demo_paths()
    if not paths:
        raise UsageError("no PATH given (name files or directories, or use --demo)")
    reports = check_paths(collect_paths(paths), settings)
    for report in reports:
        if report.error is not None:
            sys.stderr.write(f"{report.path}:{report.error_line}: Q901 unreadable: {report.error}\n")
        elif report.skipped is not None and not args.quiet:
            sys.stderr.write(f"{report.path}: skipped ({report.skipped})\n")

    if args.format == "json":
        from ..output import json as json_output

        json_output.write(reports, settings, sys.stdout)
    elif args.statistics:
        text.write_statistics(reports, sys.stdout)
    else:
        text.write(reports, sys.stdout, verbose=args.verbose)
    if args.format == "text" and not args.quiet:
        text.write_summary(reports, sys.stdout)

    if any(r.error is not None for r in reports):
        return EXIT_ERROR
    return EXIT_FINDINGS if any(r.n_findings for r in reports) else EXIT_CLEAN
