"""``affinity fix PATH... [-o OUT] [--dry-run] [--format json]``: refine the flagged quads (issue 41).

Each file is linted; the quads Q101-Q103 flag at or above ``--fix-level`` are refined
with quads only (:mod:`affinity.fix`), the result re-checked in memory, and written beside
the input as ``NAME.fixed.EXT`` (``-o`` names it for a single input; ``--in-place``
replaces the input, atomically). ``--dry-run`` writes nothing and says what would be done.
A result that adds a finding of another rule at warning or above is not written unless
``--allow-new-findings``. Exit codes: 0 every flagged quad fixed (or none flagged), 1 some
left as they were (listed with the reason) or a result that adds findings, 2 a usage error or an
unreadable input (the other files are still fixed).
"""

from __future__ import annotations

import argparse
import os
import sys

from ..errors import UsageError
from . import EXIT_CLEAN, EXIT_ERROR, EXIT_FINDINGS


def _level(text: str) -> int:
    from ..fix.layout import MAX_LEVEL

    if not text.isdigit() or not 1 <= int(text) <= MAX_LEVEL:
        raise argparse.ArgumentTypeError(f"not a level from 1 to {MAX_LEVEL}: {text!r}")
    return int(text)


def _count(text: str) -> int:
    """A positive count, digits with optional ``_`` or ``,`` separators and an optional K, M or G."""
    scale = {"k": 10**3, "m": 10**6, "g": 10**9}.get(text[-1:].lower(), 1)
    digits = (text[:-1] if scale > 1 else text).replace("_", "").replace(",", "")
    if not digits.isdigit() or int(digits) == 0:
        raise argparse.ArgumentTypeError(f"not a positive count: {text!r}")
    return int(digits) * scale


def add_parser(sub) -> None:
    from ..fix.plan import MAX_BYTES_ADDED, MAX_FACES_ADDED
    from ..loaders.formats import described
    from ..rules import LEVELS
    from ..rules.wording import fix_left_code, scored, scored_span
    from ..settings import DIAGONALS, MEASURES
    from .check import _codes, _measure, _selection, _threshold, add_subdivision_arguments

    p = sub.add_parser(
        "fix", help="refine the quads the affinity rules flag, crack-free, touching nothing else",
        description=f"Refine the quads of {described()} files that {scored_span()} flag until the crease is gone: "
                    "each becomes n x n quads on its own bilinear surface (n odd), and the faces beside it are "
                    "cut into quads to meet the new edge points (no T-junction, no triangle); a face it leaves "
                    "keeps its line. The result is re-checked before it is written. Writes NAME.fixed.EXT "
                    "beside each input.",
    )
    p.add_argument("paths", nargs="+", metavar="PATH",
                   help="mesh files or directories (searched as check searches them; NAME.fixed.EXT files "
                        "found there are earlier fixes, not inputs)")
    p.add_argument("-o", "--output", metavar="OUT", help="the fixed file (one input only; default NAME.fixed.EXT)")
    p.add_argument("--in-place", action="store_true", help="replace each input with its fix (atomically)")
    p.add_argument("--dry-run", action="store_true",
                   help="write nothing; list the faces that would be refined (with n), left (with why) and added")
    p.add_argument("--format", choices=("text", "json"), default="text", help="output of --dry-run and the summary")
    p.add_argument("--fix-level", choices=tuple(reversed(LEVELS)), default="warning",
                   help=f"the lowest level of a {scored_span()} finding that is fixed (default: warning)")
    p.add_argument("--max-refine", type=_level, default=9, metavar="N",
                   help="refine a quad into at most N x N quads, N rounded up to odd (default 9); one that needs "
                        "more is left and reported as needing a re-UV")
    p.add_argument("--max-faces-added", type=_count, default=MAX_FACES_ADDED, metavar="N",
                   help=f"the output budget in faces added per file (default {MAX_FACES_ADDED:,}); past it the "
                        "worst quads are refined first and the rest left over-budget")
    p.add_argument("--max-bytes-added", type=_count, default=MAX_BYTES_ADDED, metavar="N",
                   help=f"the output budget in bytes added per file, estimated (default {MAX_BYTES_ADDED:,}; "
                        "K, M, G allowed)")
    p.add_argument("--allow-new-findings", action="store_true",
                   help="write a result even where it adds a finding of another rule at warning or above")
    add_subdivision_arguments(p)
    p.add_argument("--refine-nonplanar", action="store_true",
                   help=f"refine the quads {fix_left_code('nonplanar')} flags too: their pieces follow the quad's "
                        "bilinear surface, "
                        "not the folded split the input draws (default: left)")
    p.add_argument("--select", type=_selection,
                   help=f"rule codes or prefixes whose findings are fixed, e.g. {scored()[0]}")
    p.add_argument("--ignore", type=_codes, help="rule codes or prefixes not fixed")
    p.add_argument("--threshold", type=_threshold, action="append", default=[], metavar="[CODE=]VALUE",
                   help="as in check: the value each refined quad's pieces must get under")
    p.add_argument("--measure", type=_measure, metavar="{" + ",".join(MEASURES) + "}", help="as in check")
    p.add_argument("--diagonal", choices=DIAGONALS, help="as in check")
    p.add_argument("--texture-size", type=int, metavar="PX", help="as in check")
    p.add_argument("-q", "--quiet", action="store_true", help="text: one summary line per file, no line per face")
    p.add_argument("--config", metavar="FILE", help="as in check")
    p.add_argument("--isolated", action="store_true", help="ignore configuration files")
    p.set_defaults(run=run)


def _format(path: str) -> str:
    """The format family of a path by its extension: ``"usd"`` for every USD suffix, else the suffix."""
    from ..fix.write import USD_SUFFIXES

    extension = os.path.splitext(path)[1].lower()
    return "usd" if extension in USD_SUFFIXES else extension.lstrip(".")


def _output_path(path: str, args) -> str:
    from ..fix.write import default_output

    if args.in_place:
        return path
    return args.output or default_output(path)


def _inputs(paths: list[str], resolver) -> list[str]:
    """The mesh files of ``paths``: files as given, directories walked (earlier fixes found there left out)."""
    from ..pipeline.files import collect_paths

    found = collect_paths(paths, lambda folder: resolver.resolve(folder).settings,
                          lambda message: sys.stderr.write(message + "\n"))
    earlier = [path for path in found if path not in paths and os.path.splitext(path)[0].endswith(".fixed")]
    return [path for path in found if path not in earlier]


def run(args) -> int:
    from ..config import ConfigError, Resolver
    from .check import _overrides

    try:
        resolver = Resolver(_overrides(args), config=args.config, isolated=args.isolated)
    except ConfigError as err:
        raise UsageError(str(err)) from None
    args.paths = _inputs(args.paths, resolver)
    if args.output and len(args.paths) > 1:
        raise UsageError("-o names one output: give one input, or none of -o for NAME.fixed.EXT beside each")
    if args.output and args.in_place:
        raise UsageError("-o and --in-place exclude each other")
    if args.output and os.path.exists(args.output) and os.path.samefile(args.output, args.paths[0]):
        raise UsageError(f"-o {args.output} is the input; use --in-place to replace it")
    if args.output and _format(args.output) != _format(args.paths[0]):
        raise UsageError(f"-o {args.output}: the fix of {args.paths[0]} is written in its own format "
                         f"({_format(args.paths[0]) or 'none'})")
    if args.in_place and any(_format(path) == "usd" for path in args.paths):
        raise UsageError("--in-place: a USD stage's fix is a layer over it, written beside it (drop --in-place)")
    results = [_fix_one(path, resolver, args) for path in args.paths]
    if args.format == "json":
        import json

        json.dump({"files": results}, sys.stdout, indent=1)
        sys.stdout.write("\n")
    if any("error" in r for r in results):
        return EXIT_ERROR
    return EXIT_FINDINGS if any(r.get("left") or r.get("new_findings") for r in results) else EXIT_CLEAN


def _fix_one(path: str, resolver, args) -> dict:
    """Fix (or, with --dry-run, plan) one file; its entry of the JSON document. Never raises for bad input."""
    from ..errors import MeshError, SkippedFile, internal_error
    from ..fix import FixSettings, plan_fix
    from ..fix.plan import profile_subdivides
    from ..loaders import load
    from ..output.names import printable
    from ..rules.wording import unreadable_line

    if _format(path) == "fbx":
        from ..loaders.fbx import NO_FIX

        sys.stderr.write(f"{path}: {NO_FIX}\n")
        return {"path": path, "error": NO_FIX}
    try:
        settings = resolver.resolve(path).settings.for_file(path)
        mesh = load(path)
        inline = _inline_ignores(path, mesh)
    except SkippedFile as skip:
        sys.stderr.write(f"{printable(path)}: skipped ({skip.reason})\n")
        return {"path": path, "skipped": skip.reason}
    except MeshError as err:
        sys.stderr.write(unreadable_line(printable(path), err.reason, err.line) + "\n")
        return {"path": path, "error": err.reason, "line": err.line}
    try:
        plan = plan_fix(mesh, FixSettings(lint=settings, level=args.fix_level, max_refine=args.max_refine,
                                          refine_nonplanar=args.refine_nonplanar, inline=inline,
                                          subdivided=profile_subdivides(settings, _format(path) == "usd"),
                                          max_faces_added=args.max_faces_added,
                                          max_bytes_added=args.max_bytes_added))
        entry = plan_entry(path, mesh, plan)
        refused = plan.new_findings and not args.allow_new_findings
        if not args.dry_run and not plan.empty and not refused:
            from ..fix.write import write_fixed

            out = _output_path(path, args)
            if not args.in_place:
                from ..atomic import refuse_unsafe

                refuse_unsafe(out, args.paths)
            entry["notes"] = write_fixed(path, out, mesh, plan, f"affinity fix: {summary(plan)}")
            entry["output"] = out
    except OSError as err:
        reason = f"cannot write {_output_path(path, args)}: {err.strerror or err}"
        sys.stderr.write(f"{printable(path)}: {reason}\n")
        return {"path": path, "error": reason}
    except Exception as err:  # one file's failure never stops the others, nor shows a traceback
        reason = internal_error(err)
        sys.stderr.write(f"{printable(path)}: {reason}\n")
        return {"path": path, "error": reason}
    if args.format == "text":
        write_text(entry, args.dry_run, sys.stdout, args.quiet)
    return entry


def _inline_ignores(path: str, mesh) -> list:
    """The ``# affinity: ignore[...]`` comments of an OBJ file, as ``affinity check`` reads them."""
    from ..loaders import read_source, reads_whole
    from ..loaders.suppress import inline_ignores

    return inline_ignores(read_source(path), mesh.face_line) if reads_whole(path) else []


def summary(plan) -> str:
    """One line: quads refined, faces re-cut, faces added, quads left."""
    left = f", {len(plan.left_faces)} flagged quads left" if len(plan.left_faces) else ""
    return (f"{len(plan.refine_faces)} quads refined, {len(plan.transition_faces)} faces cut into quads to meet "
            f"them, {plan.faces_added:+d} faces{left}")


def where(path: str, mesh, face: int) -> str:
    """How a text line names a face: ``path:line:1`` (design.md), ``path:/prim/path:face N`` in a USD stage."""
    numbered = as_in_check(mesh, face)
    if "prim" not in numbered:
        return f"{path}:{int(mesh.face_line[face])}:1"
    return f"{path}:{numbered['prim']}:face {numbered['face']}"


def as_in_check(mesh, face: int) -> dict:
    """A face as ``affinity check --format json`` numbers it: ``face`` in file order, or in a USD stage
    ``face`` within its mesh prim and ``prim`` the prim's path."""
    if mesh.prim_face_start is None:
        return {"face": face}
    group = int(mesh.face_group[face])
    return {"face": face - int(mesh.prim_face_start[group]), "prim": mesh.group_names[group]}


def plan_entry(path: str, mesh, plan) -> dict:
    """The JSON entry of a file's plan (design.md: ``refine``, ``left``; the rest is for people). Faces are
    numbered as in the check's JSON (:func:`as_in_check`)."""
    lines = mesh.face_line
    return {
        "path": path,
        "faces": mesh.n_faces,
        "refine": [{**as_in_check(mesh, f), "n": n, "line": int(lines[f]), "where": where(path, mesh, f),
                    "code": code, "before": before, "after": after, "unit": unit}
                   for f, n, code, before, after, unit in zip(plan.refine_faces.tolist(), plan.refine_n.tolist(),
                                                              plan.codes.tolist(), plan.before.tolist(),
                                                              plan.after.tolist(), plan.units.tolist())],
        "left": [{**as_in_check(mesh, f), "reason": reason, "line": int(lines[f]), "where": where(path, mesh, f)}
                 for f, reason in zip(plan.left_faces.tolist(), plan.left_reasons.tolist())],
        "transitions": [as_in_check(mesh, f) if mesh.prim_face_start is not None else f
                        for f in plan.transition_faces.tolist()],
        "faces_added": plan.faces_added,
        "faces_added_bound": plan.faces_added_bound,
        "bytes_added": plan.bytes_added,
        "new_findings": [{**as_in_check(mesh, d["face"]), "code": d["code"], "where": where(path, mesh, d["face"])}
                         for d in plan.new_findings],
    }


#: What a left face's text line says, by reason.
LEFT_WHY = {
    "over-cap": "needs more than --max-refine: re-UV it",
    "over-budget": "past the output budget (--max-faces-added, --max-bytes-added)",
    "still-flagged": "its refinement still reads over the threshold: left as it was",
    "subdivided": "the profile draws the subdivided surface",
}


def write_text(entry: dict, dry_run: bool, out, quiet: bool = False) -> None:
    """The text of one file: a line per refined and per left quad (``path:line:col: ... [face F]``; not when
    ``quiet``), then what was (or would be) done."""
    from ..rules import number_text

    path = entry["path"]
    verb = "would refine" if dry_run else "refined"
    for r in [] if quiet else entry["refine"]:
        change = f"{number_text(r['before'])} -> {number_text(r['after'])}"
        out.write(f"{r['where']}: {verb} n={r['n']}: {r['code']} {change} {r['unit']} [face {r['face']}]\n")
    for r in [] if quiet else entry["left"]:
        why = LEFT_WHY.get(r["reason"], "not refined")
        out.write(f"{r['where']}: left ({r['reason']}): {why} [face {r['face']}]\n")
    for r in entry["new_findings"]:
        out.write(f"{r['where']}: the result adds {r['code']} on its new faces [face {r['face']}]\n")
    for note in entry.get("notes", []):
        out.write(f"{path}: note: {note}\n")
    done = f"{verb} {len(entry['refine'])} quads, cut {len(entry['transitions'])} neighbours into quads"
    added = f"{entry['faces_added']:+d} faces, about {entry['bytes_added']:+,d} bytes"
    if "output" in entry:
        target = f" -> {entry['output']}"
    elif entry["new_findings"] and entry["refine"]:
        target = ", not written: it adds findings (--allow-new-findings writes it)"
    else:
        target = "" if dry_run or entry["refine"] else ", nothing to write"
    out.write(f"{path}: {done}, {added}, {len(entry['left'])} left{target}\n")
