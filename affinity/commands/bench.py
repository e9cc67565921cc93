"""``affinity bench [MESH...] [--quick] -o DIR``: error against run time, every method and hybrid setting.

Without MESH it studies the built-in scenes (the paper's figures and a
nonplanar quad strip); MESH may name files or folders of meshes. ``--quick``
keeps three small built-in scenes at a small size and finishes in seconds (for
CI). Writes ``study.csv``, ``summary.md`` and PNG charts into DIR; ``--table`` puts the CSV elsewhere
(the committed run writes the package's table, which the demo report reads).
"""

from __future__ import annotations

import sys

from ..errors import UsageError
from . import EXIT_CLEAN, image_size, require


def add_parser(sub) -> None:
    p = sub.add_parser(
        "bench", help="measure error against the exact reference and run time of every method",
        description="Render every scene with split, mvc, bilinear, projective, exact and the hybrid at a sweep of "
                    "settings; time them and compare each with exact. Writes study.csv, summary.md and charts.",
    )
    p.add_argument("meshes", nargs="*", metavar="MESH",
                   help="mesh files or folders to study (default: the built-in scenes)")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="folder for the CSV, summary and charts")
    p.add_argument("--table", metavar="CSV",
                   help="write the CSV here instead of DIR/study.csv (the committed study: --table package, the "
                        "package's affinity/data/study/study.csv that the demo report reads)")
    p.add_argument("--quick", action="store_true", help="three small built-in scenes, small images, two repeats")
    p.add_argument("--route", choices=["view", "lint"], default="view",
                   help="lint: also sweep the lint threshold, in the error and the barycentric reading")
    p.add_argument("--size", type=image_size, metavar="WxH", help="image size (default 800x600, 240x180 with --quick)")
    p.add_argument("--repeat", type=int, metavar="N", help="timed runs per configuration (default 7, 2 with --quick)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    p.set_defaults(run=run)


def _command_line(args) -> str:
    """The command as it could be typed again (for the summary's header)."""
    words = ["affinity bench", *args.meshes, "-o", args.output]
    words += ["--table", args.table] if args.table else []
    words += ["--quick"] if args.quick else []
    words += ["--route", args.route] if args.route != "view" else []
    words += [f"--size {args.size[0]}x{args.size[1]}"] if args.size else []
    words += [f"--repeat {args.repeat}"] if args.repeat is not None else []
    return " ".join(words)


def run(args) -> int:
    import dataclasses

    require(("PIL", "matplotlib"), "report")

    from ..output.names import printable
    from ..pipeline.files import collect_paths
    from ..scenes import study_scenes
    from ..study.cases import mesh_cases
    from ..study.run import PACKAGE_TABLE, run_cases, write_outputs
    from ..study.sweep import QUICK, StudySettings

    settings = QUICK if args.quick else StudySettings()
    changes = {"lint_route": args.route == "lint"}
    if args.size:
        changes["width"], changes["height"] = args.size
    if args.repeat is not None:
        if args.repeat < 1:
            raise UsageError(f"--repeat must be at least 1, got {args.repeat}")
        changes["repeat"] = args.repeat
    settings = dataclasses.replace(settings, **changes)
    cases = mesh_cases(collect_paths(args.meshes)) if args.meshes else study_scenes(quick=args.quick)

    def progress(line: str) -> None:
        if not args.quiet:
            sys.stderr.write(f"affinity bench: {line}\n")

    rows, skipped = run_cases(cases, settings, progress)
    for line in skipped:
        sys.stderr.write(f"affinity bench: skipped {line}\n")
    if not rows:
        raise UsageError("nothing could be studied" + (f": {'; '.join(skipped)}" if skipped else ""))
    try:
        table = PACKAGE_TABLE if args.table == "package" else args.table
        paths = write_outputs(rows, skipped, settings, args.output, _command_line(args), table)
    except OSError as err:
        raise UsageError(f"{printable(args.output)}: cannot write ({err.strerror or err})") from None
    progress(f"wrote {', '.join(paths)}")
    return EXIT_CLEAN
