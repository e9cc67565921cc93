"""``affinity check PATH...``: lint mesh files (see design.md for output and exit codes).

Settings come from the configuration file governing each file (``affinity.toml``
or ``[tool.affinity]`` in ``pyproject.toml``, see :mod:`affinity.config`);
every flag given on the command line replaces the configured value of its key
(thresholds per rule).
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
from typing import TYPE_CHECKING

from ..errors import UsageError
from . import EXIT_CLEAN, EXIT_ERROR, EXIT_FINDINGS

if TYPE_CHECKING:
    from ..shards.selection import AutoShard, Shard, ShardRecord


def _codes(text: str) -> list[str]:
    from ..settings import unknown_codes

    codes = [c.strip().upper() for c in text.split(",") if c.strip()]
    unknown = unknown_codes(codes)
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown rule {', '.join(unknown)}")
    return codes


def _selection(text: str) -> list[str]:
    """``--select``: at least one rule; ``--ignore`` is how a rule is switched off."""
    codes = _codes(text)
    if not codes:
        raise argparse.ArgumentTypeError("selects no rule (use --ignore to switch rules off)")
    return codes


def _threshold(text: str) -> tuple[str, float]:
    """``0.8`` (the uv rule Q101) or ``CODE=VALUE``; VALUE a finite number."""
    from ..rules.affinity import UV_DISAFFINE
    from ..rules.wording import threshold_example

    code, _, value = text.rpartition("=")
    try:
        number = float(value)
    except ValueError:
        number = math.nan
    if not math.isfinite(number):
        raise argparse.ArgumentTypeError(f"not a finite threshold: {text!r} "
                                         f"(use {threshold_example()}; --ignore switches a rule off)")
    return (code.strip().upper() or UV_DISAFFINE), number


def _count(text: str) -> int:
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"not a positive number: {text!r}")
    return int(text)


def _jobs(text: str) -> int:
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"not a number of processes: {text!r}")
    return int(text)


def _shard(text: str) -> Shard | AutoShard:
    from ..shards.selection import parse_shard

    return parse_shard(text)


def _resolved_shard(spec: Shard | AutoShard | None) -> Shard | None:
    """``--shard``'s shard: ``auto`` read from the farm's environment (a UsageError when it names none)."""
    if spec is None:
        return None  # the shards' module (and hashlib) stay off a plain check's path
    from ..shards.selection import AutoShard, shard_from_environment

    if not isinstance(spec, AutoShard):
        return spec
    try:
        return shard_from_environment(spec, os.environ)
    except ValueError as err:
        raise UsageError(str(err)) from None


def _time(text: str) -> float:
    try:
        time = float(text)
    except ValueError:
        time = float("nan")
    if not math.isfinite(time):
        raise argparse.ArgumentTypeError(f"not a time code: {text!r}")
    return time


def _measure(text: str) -> str:
    """--measure NAME; the deprecated ``misplacement`` means ``error`` (one warning line on stderr)."""
    from ..settings import MEASURES, measure_name

    measure = measure_name(text, "--measure")
    if measure is None:
        raise argparse.ArgumentTypeError(f"invalid choice: {text!r} (choose from {', '.join(MEASURES)})")
    return measure


def add_parser(sub) -> None:
    from ..loaders.formats import described
    from ..output import FORMATS
    from ..pipeline.progress import MODES as PROGRESS_MODES
    from ..rules.wording import bare_threshold_help, measure_help, select_example
    from ..settings import DIAGONALS, MEASURES

    p = sub.add_parser(
        "check", help="lint mesh files for quad affinity and shape problems",
        description=f"Lint {described()} files "
                    "(directories are searched recursively). "
                    "Settings come from affinity.toml or [tool.affinity] in pyproject.toml, found by "
                    "walking up from each file; flags given here win.",
    )
    p.add_argument("paths", nargs="*", metavar="PATH", help="files or directories (default: .)")
    p.add_argument("--demo", action="store_true", help="also check the bundled demo meshes")
    p.add_argument("--format", choices=FORMATS, default="text",
                   help="text (default), json, sarif (code scanning), github (workflow annotations), junit")
    p.add_argument("--select", type=_selection, help=f"rule codes or prefixes to enable, e.g. {select_example()}")
    p.add_argument("--ignore", type=_codes, help="rule codes or prefixes to disable")
    p.add_argument(
        "--threshold", type=_threshold, action="append", default=[], metavar="[CODE=]VALUE",
        help=bare_threshold_help(),
    )
    p.add_argument("--measure", type=_measure, metavar="{" + ",".join(MEASURES) + "}", help=measure_help())
    p.add_argument("--diagonal", choices=DIAGONALS,
                   help="which split diagonal the affinity test measures (default: both)")
    p.add_argument("--texture-size", type=int, metavar="PX",
                   help="texture size for texel units when the mesh names no readable map_Kd (default 1024)")
    add_subdivision_arguments(p)
    usd = p.add_argument_group("USD stages")
    usd.add_argument("--time", type=_time, metavar="T",
                     help="read the stage at time code T (default: the earliest time sample)")
    usd.add_argument("--uv-primvar", metavar="NAME",
                     help="texture coordinates from primvar NAME (default: st, else the first texCoord2f primvar); "
                          "in an FBX file, the uv set NAME (default: the first)")
    usd.add_argument("--all-variants", action="store_true",
                     help="read the textures of every variant's material binding (default: the stage's selection)")
    config = p.add_argument_group("configuration")
    config.add_argument("--config", metavar="FILE",
                        help="use this affinity.toml/pyproject.toml for every file instead of searching")
    config.add_argument("--isolated", action="store_true", help="ignore configuration files")
    config.add_argument("--show-settings", action="store_true",
                        help="print the resolved settings (and the file they came from) and exit")
    known = p.add_argument_group("baseline")
    known.add_argument("--baseline", metavar="FILE", help="report only findings not recorded in this baseline")
    known.add_argument("--write-baseline", metavar="FILE",
                       help="record every current finding in FILE (counts per file, group and rule) and exit")
    p.add_argument("-j", "--jobs", type=_jobs, metavar="N",
                   help="check files in N processes (default: all CPUs, fewer when the files are small)")
    add_gate_arguments(p)
    p.add_argument("--max-findings", type=_count, metavar="N",
                   help="json/junit/sarif/github: keep the worst N findings per file and rule, and say what was "
                        "truncated (without it sarif and github keep the worst 5,000 of the whole run)")
    p.add_argument("--show-files", action="store_true", help="list the files that would be checked and exit")
    p.add_argument("--shard", type=_shard, metavar="K/N",
                   help="check only shard K of N (1-based): each file in exactly one shard, the same on every "
                        "machine; affinity merge joins the shards' --format json results into one. auto[/N]: "
                        "K (and N) from JOB_COMPLETION_INDEX (Kubernetes; N from /N or AFFINITY_SHARD_COUNT) "
                        "or CI_NODE_INDEX/CI_NODE_TOTAL (GitLab)")
    p.add_argument("-o", "--output-file", metavar="PATH",
                   help="write the output to PATH (whole or not at all); - is standard output")
    p.add_argument("--resume", metavar="RESULT.jsonl",
                   help="keep each file's result in RESULT.jsonl as it finishes (JSON lines, appended); rerun "
                        "with the same file after a kill to check only the files not yet in it. affinity merge "
                        "joins the shards' journals")
    p.add_argument("--progress", choices=PROGRESS_MODES, default="auto",
                   help="progress on stderr: auto (a bar on a terminal), bar, json (one JSON line a second, for "
                        "farms) or none")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="check the files on a Dask cluster: a scheduler address, env (DASK_SCHEDULER_ADDRESS) "
                        "or local:N (N local worker processes); needs the distributed extra. "
                        "none checks on this machine whatever the configuration says")
    p.add_argument("--no-cache", action="store_true",
                   help="check every file again instead of reusing the results of unchanged files "
                        "(cache folder: AFFINITY_CACHE_DIR, else the user cache folder)")
    add_display_arguments(p)
    p.set_defaults(run=run)


def add_subdivision_arguments(p) -> None:
    """The options that say which surface Q101-Q103 measure (design.md, "Subdivision")."""
    from ..rules.wording import scored_span
    from ..settings import FVAR_INTERPOLATIONS, PROFILES

    group = p.add_argument_group("subdivision")
    group.add_argument("--subdivision", type=_subdivision, metavar="{cage,auto,level:N,limit}",
                       help=f"measure {scored_span()} on the cage, on the mesh's own scheme at the profile's level "
                            "(auto, the default), on the surface refined N times, or on the limit surface")
    group.add_argument("--profile", choices=tuple(PROFILES),
                       help="the renderer whose level auto measures: game and storm the cage (game is the "
                            "default), blender-viewport level 1, blender-render level 2, film the limit surface")
    group.add_argument("--fvar-interpolation", choices=FVAR_INTERPOLATIONS,
                       help="the uv rule of OBJ/PLY/OFF meshes refined with --subdivision level:N "
                            "(default cornersPlus1, USD's)")


def _subdivision(text: str) -> str:
    from ..settings import subdivision_name

    name = subdivision_name(text)
    if name is None:
        raise argparse.ArgumentTypeError(f"invalid value: {text!r} (choose cage, auto, limit or level:N)")
    return name


def add_gate_arguments(p) -> None:
    """The options that decide the exit code :func:`publish` returns."""
    from ..rules import LEVELS

    p.add_argument("--fail-on", choices=LEVELS, default="error",
                   help="the lowest level whose findings make exit 1 (default: error, a plainly visible "
                        "crease; warning also fails on the milder ones)")
    p.add_argument("--level", choices=LEVELS,
                   help="show only the findings at this level or above: error prints what fails the default gate "
                        "(default: every level, in JUnit warning; the exit code still counts every finding)")
    p.add_argument("--exit-zero", action="store_true",
                   help="exit 0 even with findings (unreadable input and --fail-on-skip still exit 2)")
    p.add_argument("--fail-on-skip", action="store_true",
                   help="exit 2 when a file was skipped (a Git LFS pointer, a USD stage with no mesh), so a "
                        "checkout without 'git lfs pull' cannot pass with nothing checked")


def add_display_arguments(p) -> None:
    """The options of what :func:`publish` writes besides ``--format`` and ``-o``."""
    p.add_argument("--statistics", action="store_true",
                   help="text: counts per rule instead of findings; json/sarif/github/junit: counts added")
    p.add_argument("--verbose", action="store_true", help="show every finding in text output")
    p.add_argument("-q", "--quiet", action="store_true", help="print findings and nothing else")


def _overrides(args) -> dict:
    """Settings field -> value for every setting flag given on the command line."""
    from ..settings import unthresholded_codes

    thresholds = dict(args.threshold)
    bad = unthresholded_codes(list(thresholds))
    if bad:
        raise UsageError(f"--threshold: {', '.join(bad)} is not a rule with a threshold")
    if args.texture_size is not None and args.texture_size <= 0:
        raise UsageError("--texture-size must be a positive number of pixels")
    given = {
        "select": args.select, "ignore": args.ignore, "measure": args.measure,
        "diagonal": args.diagonal, "texture_size": args.texture_size,
        "subdivision": args.subdivision, "profile": args.profile, "fvar_interpolation": args.fvar_interpolation,
    }
    return {"thresholds": thresholds, **{k: v for k, v in given.items() if v is not None}}


def report_problems(reports, quiet: bool, skips_fail: bool = False) -> None:
    """Unreadable files (always), skipped files (unless quiet; always when they fail the run) and the
    loader's notes (unless quiet), one line each on stderr; a note several files say alike (a layer they all
    compose) once, at the first."""
    from ..output.names import printable
    from ..rules.wording import unreadable_line

    said = set()
    for report in reports:
        path = printable(report.path)
        if report.error is not None:
            sys.stderr.write(unreadable_line(path, report.error, report.error_line) + "\n")
        elif report.skipped is not None and (skips_fail or not quiet):
            sys.stderr.write(f"{path}: skipped ({report.skipped})\n")
        for note in [] if quiet else [note for note in report.notes if note not in said]:
            said.add(note)
            sys.stderr.write(f"{path}: note: {note}\n")


@contextlib.contextmanager
def _result_cache(args, run_options: dict):
    """The result cache, committed and closed at the end; None with ``--no-cache`` or ``cache = false``.

    A shard keeps its own cache file (a farm's workers never share one database over network storage).
    """
    if args.no_cache or not run_options.get("cache", True):
        yield None
        return
    from ..pipeline.cache import ResultCache, cache_folder

    cache = ResultCache(cache_folder(), shard=args.shard)
    try:
        yield cache
    finally:
        cache.close()


def _cluster(args, run_options: dict, show_dashboard: bool):
    """What :func:`~affinity.pipeline.check.check_files` calls to reach the Dask cluster of ``--scheduler``
    (or of the configured ``scheduler``); None for a run on this machine (no scheduler, or ``none``).

    A bad scheduler spec or a missing ``distributed`` extra fails now; the
    cluster itself is reached only when some file is not in the cache. With
    ``show_dashboard`` its dashboard link goes to stderr once connected.
    """
    spec = args.scheduler or run_options.get("scheduler")
    if spec is None or spec == "none":
        return None
    from ..pipeline.cluster import connect, dashboard_link, scheduler_address

    address = scheduler_address(spec)
    from . import require

    require(("distributed",), "distributed")
    if args.jobs is not None:
        sys.stderr.write(f"affinity: warning: --jobs {args.jobs} is ignored with --scheduler: "
                         "the cluster's workers check the files\n")

    @contextlib.contextmanager
    def on_cluster():
        with connect(address) as client:
            link = dashboard_link(client) if show_dashboard else None
            if link:
                sys.stderr.write(f"Dask dashboard: {link}\n")
            yield client

    return on_cluster


def _tasks(resolver, paths: list[str]) -> list:
    """``(file, settings)`` for every mesh file to check: excluded files dropped, per-file ignores applied."""
    from ..pipeline.files import collect_paths

    def warn(message: str) -> None:
        sys.stderr.write(message + "\n")

    return [
        (path, settings.for_file(path))
        for path in collect_paths(paths, lambda folder: resolver.resolve(folder).settings, warn)
        if not (settings := resolver.resolve(path).settings).is_excluded(path)
    ]


def _shard_tasks(tasks: list, shard: Shard, resolver, baseline: bool) -> tuple[list, ShardRecord]:
    """The tasks of shard ``shard`` (:mod:`affinity.shards.selection`), in run order, and the record its
    result carries. Paths are hashed relative to the folder of the configuration file governing the
    working directory, else to the working directory."""
    from ..shards.selection import select_shard

    source = resolver.resolve(os.curdir).source
    root = os.getcwd() if source is None else os.path.dirname(os.path.abspath(source))
    positions, record = select_shard([path for path, _ in tasks], shard, root, baseline)
    return [tasks[i] for i in positions], record


@contextlib.contextmanager
def _journal(path: str | None, settings, tasks: list, shard: ShardRecord | None):
    """The journal of ``--resume path`` (:mod:`affinity.shards.journal`), closed at the end; None without it."""
    if path is None:
        yield None
        return
    from ..atomic import refuse_unsafe
    from ..output.names import printable
    from ..shards.journal import Journal, header_of
    from ..shards.results import ResultError
    from ..shards.selection import run_digest

    header = header_of(settings, len(tasks), run_digest([p for p, _ in tasks]), shard)
    try:
        refuse_unsafe(path, [p for p, _ in tasks])  # a journal is written: never through a link, never an input
        journal = Journal(path, header)
    except ResultError as err:
        raise UsageError(f"--resume {printable(path)}: {err}") from None
    except OSError as err:
        raise UsageError(f"--resume {printable(path)}: cannot write it: {err.strerror or err}") from None
    try:
        yield journal
    finally:
        journal.close()


def _journaled(journal, todo: list[int], settings, progress):
    """A ``progress`` for :func:`check_files` that appends each finished file to ``journal`` (as the file at
    ``todo[i]`` of the run) before passing it on to ``progress`` (None: to nobody)."""

    def record(results, total):
        for i, report in results:
            journal.record(todo[i], report, settings)
            yield i, report

    if progress is None:
        return record
    return lambda results, total: progress(record(results, total), total)


#: The lowest level JUnit lists without ``--level``: its testcases are what may fail, and info findings never
#: fail a gate (a folder's 150,000 of them were 60 MB of passing testcases).
JUNIT_LEVEL = "warning"


def _require_some_rule(settings) -> None:
    """A usage error when ``--select``/``--ignore`` (with the configuration) leave no rule to check: a gate
    that checks nothing would pass every file, silently."""
    from ..rules.registry import resolve_codes

    if not resolve_codes(settings.select, settings.ignore):
        raise UsageError(f"the selection leaves no rule to check (select {', '.join(settings.select or ['ALL'])}; "
                         f"ignore {', '.join(settings.ignore or [])})")


def _write_baseline(reports, path: str, quiet: bool) -> None:
    from ..pipeline import baseline

    recorded = baseline.record(reports, path)
    baseline.write(recorded, path)
    if not quiet:
        from ..output.names import printable

        files = len({key[0] for key in recorded.counts})
        sys.stderr.write(f"Wrote {sum(recorded.counts.values())} findings in {files} files to the baseline "
                         f"{printable(path)}.\n")


def run(args) -> int:
    from ..config import Resolver
    from ..loaders.usd import UsdOptions
    from ..output import CheckRun
    from ..pipeline.authored import one_report_per_authored_mesh
    from ..pipeline.check import check_files
    from ..pipeline.progress import progress_for

    if args.baseline and args.write_baseline:
        raise UsageError("--baseline and --write-baseline exclude each other")
    if args.shard is not None and args.write_baseline:
        raise UsageError("--write-baseline records the whole run's findings: run it without --shard")
    if args.resume is not None and (args.baseline or args.write_baseline):
        raise UsageError("--resume keeps every finding of each file: apply a baseline to the merged result, "
                         "not to a journal")
    args.shard = _resolved_shard(args.shard)
    resolver = Resolver(_overrides(args), config=args.config, isolated=args.isolated)
    _require_some_rule(resolver.resolve(os.curdir).settings)
    paths = list(args.paths)
    if args.demo:
        from ..scenes import demo_paths

        paths += demo_paths()
    if args.show_settings:
        from ..output.show_settings import write_settings

        _write_output_file(args.output_file, lambda out: write_settings(resolver, paths or [os.curdir], out))
        return EXIT_CLEAN
    if args.baseline:
        from ..pipeline import baseline

        known = baseline.read(args.baseline)  # before the check: a bad baseline fails fast

    tasks = _tasks(resolver, paths)
    shard = None
    if args.shard is not None:
        tasks, shard = _shard_tasks(tasks, args.shard, resolver, bool(args.baseline))
    if args.show_files:
        from ..output.names import printable

        _write_output_file(args.output_file, lambda out: out.writelines(printable(path) + "\n" for path, _ in tasks))
        return EXIT_CLEAN
    run_options = resolver.run_options()
    settings = resolver.resolve(os.curdir).settings
    with _journal(args.resume, settings, tasks, shard) as journal:
        done = {} if journal is None else journal.done
        todo = [i for i in range(len(tasks)) if i not in done]
        progress = progress_for(args.progress, len(todo))
        cluster = _cluster(args, run_options, len(todo) > 1 and sys.stderr.isatty())
        if journal is not None:
            progress = _journaled(journal, todo, settings, progress)
        with _result_cache(args, run_options) as cache:
            fresh = check_files([tasks[i] for i in todo], args.jobs, progress,
                                usd=UsdOptions(args.time, args.uv_primvar, args.all_variants), cache=cache,
                                cluster=cluster)
    reports = [done[i] if i in done else None for i in range(len(tasks))]
    for i, report in zip(todo, fresh):
        reports[i] = report
    reports = one_report_per_authored_mesh(reports)
    report_problems(reports, args.quiet, args.fail_on_skip)
    if args.write_baseline:
        _write_baseline(reports, args.write_baseline, args.quiet)
        return EXIT_ERROR if _failed(reports, args.fail_on_skip) else EXIT_CLEAN

    check_run = CheckRun(reports, settings,
                         max_findings=args.max_findings, statistics=args.statistics, shard=shard,
                         fail_on=args.fail_on)
    if args.baseline:
        check_run.reports, check_run.baselined = baseline.apply(reports, known)
    return publish(check_run, args)


def publish(check_run, args) -> int:
    """Write ``check_run`` as ``args`` asks (``--format``, ``-o``, ``--level``, ``--verbose``, ``--statistics``,
    ``-q``) and return the run's exit code (``--fail-on``, ``--exit-zero``, ``--fail-on-skip``; design.md): the
    gate counts every finding, whatever ``--level`` shows."""
    gated = check_run.reports
    level = args.level if args.level is not None or args.format != "junit" else JUNIT_LEVEL
    if level is not None:
        from ..output import at_or_above

        check_run.reports, check_run.hidden = at_or_above(check_run.reports, level)
    inputs = [report.path for report in check_run.reports] + list(getattr(args, "results", []))
    _write_output_file(args.output_file, lambda out: _write_output(check_run, args, out), inputs)
    if _failed(check_run.reports, args.fail_on_skip):
        return EXIT_ERROR
    return EXIT_CLEAN if args.exit_zero or not _fails(gated, args.fail_on) else EXIT_FINDINGS


def _failed(reports, fail_on_skip: bool) -> bool:
    """Whether the run exits 2 whatever its findings: an unreadable file, or a skipped one with ``--fail-on-skip``."""
    return any(r.error is not None or (fail_on_skip and r.skipped is not None) for r in reports)


def _fails(reports, fail_on: str) -> bool:
    """Whether any finding is at level ``fail_on`` or above (error > warning > info)."""
    from ..rules import LEVELS

    return any(len(h) and h.level_ranks().min() <= LEVELS.index(fail_on) for r in reports for h in r.hits)


def _write_output_file(path: str | None, write, inputs=()) -> None:
    """``write(out)`` to stdout, or to ``path`` atomically (a failed run leaves no partial file; ``-`` is
    standard output, written whole too); never through a link to a file, nor over one of ``inputs``
    (:func:`affinity.atomic.refuse_unsafe`)."""
    if path is None:
        write(sys.stdout)
        return
    from ..atomic import atomic_write, refuse_unsafe

    try:
        refuse_unsafe(path, inputs)
        with atomic_write(path) as out:
            write(out)
    except OSError as err:
        from ..output.names import printable

        raise UsageError(f"{printable(path)}: cannot write the output: {err.strerror or err}") from None


def _write_output(check_run, args, out) -> None:
    from ..output import text, writer

    if args.format == "text":
        text.write(check_run, out, verbose=args.verbose, statistics=args.statistics, summary=not args.quiet)
    else:
        writer(args.format)(check_run, out)
