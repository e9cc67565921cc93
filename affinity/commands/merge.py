"""``affinity merge RESULT.json...``: the JSON results of a run's shards (``affinity check --shard K/N
--format json``) written as one result, as if one run had checked every file (see
:mod:`affinity.shards.merge`): one SARIF run, the same summary, the exit code of the gate over all files.
"""

from __future__ import annotations

import sys

from . import EXIT_ERROR


def add_parser(sub) -> None:
    from ..output import FORMATS
    from .check import add_display_arguments, add_gate_arguments

    p = sub.add_parser(
        "merge", help="join the JSON results of the shards of a run (check --shard K/N) into one result",
        description="Read the --format json results of every shard of one run (affinity check --shard K/N) "
                    "and write one result, as if one run had checked every file. Exit 2 when an input is "
                    "unreadable, truncated by --max-findings or from another run, or a shard is missing "
                    "or given twice.",
    )
    p.add_argument("results", nargs="+", metavar="RESULT.json", help="the shards' JSON results, in any order")
    p.add_argument("--format", choices=FORMATS, default="text",
                   help="text (default), json, sarif (code scanning), github (workflow annotations), junit")
    p.add_argument("-o", "--output-file", metavar="PATH",
                   help="write the output to PATH (whole or not at all); - is standard output")
    add_gate_arguments(p)
    add_display_arguments(p)
    p.set_defaults(run=run)


def run(args) -> int:
    from ..output import CheckRun
    from ..pipeline.authored import one_report_per_authored_mesh
    from ..shards.merge import MergeError, merge_results
    from .check import publish, report_problems

    try:
        merged = merge_results(args.results)
    except MergeError as err:
        sys.stderr.writelines(f"affinity merge: error: {problem}\n" for problem in err.problems)
        return EXIT_ERROR
    reports = one_report_per_authored_mesh(merged.reports)
    report_problems(reports, args.quiet, args.fail_on_skip)
    check_run = CheckRun(reports, merged.settings, baselined=merged.baselined, statistics=args.statistics,
                         fail_on=args.fail_on)
    return publish(check_run, args)
