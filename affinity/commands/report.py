"""``affinity report [MESH...] [-o report.html]``: the HTML report, the product's main job.

Without MESH it reports on the built-in demo scenes. The page is one
self-contained file (pictures embedded, no network). An unreadable mesh is a
failed row in the report and a ``Q901`` line on stderr, a skipped one (a Git LFS
pointer, a USD stage without a mesh) a skipped row, and the exit code is 2;
otherwise 0 (findings are the report's content, not a failure). A single MESH
that is skipped, or a report that cannot be written, is an error (exit 2) and
writes nothing.
"""

from __future__ import annotations

import argparse
import os
import sys

from ..errors import UsageError
from ..loaders.formats import described
from ..report import MAX_VIEWS, PLACE_FACES, RENDER_SIZE
from ..rules import LEVELS
from . import EXIT_CLEAN, EXIT_ERROR, camera, image_size, pixel_tolerance, require


def add_parser(sub) -> None:
    p = sub.add_parser(
        "report", help="write the HTML report: findings, renders, affinity scores",
        description="Lint, score and render MESH files (directories are searched; default: the built-in demo "
                    "scenes) into one self-contained HTML page.",
        epilog="Exit codes: 0 the report was written; 2 a usage error, an output that cannot be written (nothing "
               "is written), a single MESH that is skipped (nothing is written), or an unreadable or skipped mesh "
               "among several (the report is still written, with its row).",
    )
    p.add_argument("meshes", nargs="*", metavar="MESH", help=f"{described()} files or directories")
    p.add_argument("-o", "--output", default="report.html", metavar="HTML",
                   help="where to write the report (default: report.html)")
    p.add_argument("--up", choices=["x", "y", "z"], default=None,
                   help="world up axis (default: the stage's upAxis for USD, else guessed from the shape: z for a "
                        "surface of revolution standing on z or a shape lying on z (a car, a terrain), else y)")
    p.add_argument("--size", type=image_size, default=RENDER_SIZE, metavar="WxH",
                   help=f"size of the renders and the 3-D overview (default: {RENDER_SIZE[0]}x{RENDER_SIZE[1]})")
    p.add_argument("--camera", type=camera, metavar="EX,EY,EZ,TX,TY,TZ,FOV",
                   help="the overview's camera for every mesh (default: the whole mesh from its broad side)")
    p.add_argument("--texture", metavar="IMAGE", help="texture image for uv (default: map_Kd, else a grid)")
    p.add_argument("--pixel-tolerance", type=pixel_tolerance, default=0.5, metavar="PX",
                   help="the hybrid routes a quad to mvc when the split moves its texture by more than PX pixels")
    p.add_argument("--max-views", type=_count, default=MAX_VIEWS, metavar="N",
                   help=f"close-ups per mesh, worst flagged places first (default: {MAX_VIEWS}; 0: none)")
    p.add_argument("--place-faces", type=_positive, default=PLACE_FACES, metavar="N",
                   help=f"the most faces a close-up's place holds: a bigger group of flagged faces is cut into "
                        f"places around its worst faces (default: {PLACE_FACES})")
    p.add_argument("--fail-on", choices=LEVELS, default="error",
                   help="the level the verdict is given at, as for affinity check: the report says a mesh fails "
                        "when it has a finding at this level or above (default: error)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no result line")
    p.set_defaults(run=run)


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"not a count: {text!r} (use 0 or more)")
    return value


def _positive(text: str) -> int:
    value = _count(text)
    if value == 0:
        raise argparse.ArgumentTypeError(f"not a positive count: {text!r} (use 1 or more)")
    return value


def _check_writable(path: str) -> None:
    """Fail before the work, with a clear line, when ``path`` cannot be written."""
    from ..output.names import printable

    target = os.path.realpath(path)  # a link is written through (affinity.atomic)
    folder = os.path.dirname(target)
    if os.path.isdir(target):
        raise UsageError(f"{printable(path)}: is a directory (name the HTML file to write)")
    if os.path.exists(target) and not os.path.isfile(target):
        return  # a device or pipe, written in place
    if not os.path.isdir(folder):
        raise UsageError(f"{printable(path)}: cannot write the report: no such directory {printable(folder)}")
    if not os.access(folder, os.W_OK):
        raise UsageError(f"{printable(path)}: cannot write the report: the directory {printable(folder)} "
                         "is not writable")


def _inputs(paths: list[str], resolver) -> list:
    from ..pipeline.files import collect_paths
    from ..report.demo import MeshInput, demo_inputs

    if not paths:
        return demo_inputs()
    found = [MeshInput(path, path) for path in collect_paths(paths)
             if not resolver.resolve(path).settings.is_excluded(path)]
    if not found:
        raise UsageError("every MESH given is excluded by the configuration")
    return found


def _refuse_unsafe(path: str, inputs: list[str]) -> None:
    """Fail before the work when ``path`` is a link to a file or one of the inputs
    (:func:`affinity.atomic.refuse_unsafe`)."""
    from ..atomic import UnsafeDestination, refuse_unsafe
    from ..output.names import printable

    try:
        refuse_unsafe(path, [source for source in inputs if source])
    except UnsafeDestination as err:
        raise UsageError(f"{printable(path)}: cannot write the report: {err.strerror}") from None


def _write(path: str, html: str) -> None:
    from ..atomic import atomic_write
    from ..output.names import printable

    try:
        with atomic_write(path) as out:
            out.write(html)
    except OSError as err:
        raise UsageError(f"{printable(path)}: cannot write the report ({err.strerror or err})") from None


def run(args) -> int:
    import time

    from tqdm import tqdm

    from ..config import Resolver
    from ..output.names import printable
    from ..report.build import ReportOptions, collect_run
    from ..report.page import render_page
    from ..rules.wording import unreadable_line

    start = time.perf_counter()
    require(("PIL", "jinja2", "matplotlib", "mpmath"), "report")
    _check_writable(args.output)
    if args.texture:
        from ..draw.texture import TextureError, load_image

        try:
            load_image(args.texture)
        except TextureError as err:
            raise UsageError(str(err)) from None
    options = ReportOptions(up=args.up, size=args.size, camera=args.camera, texture=args.texture,
                            pixel_tolerance=args.pixel_tolerance, max_views=args.max_views,
                            place_faces=args.place_faces)
    resolver = Resolver({})
    inputs = _inputs(args.meshes, resolver)
    _refuse_unsafe(args.output, [mesh.path for mesh in inputs] + [args.texture or ""])
    with tqdm(total=len(inputs), unit="file", file=sys.stderr, leave=False, delay=1.0,
              disable=args.quiet or not sys.stderr.isatty()) as bar:
        report = collect_run(inputs, lambda path: resolver.resolve(path).settings.for_file(path),
                             resolver.resolve(os.curdir).settings, bar, options, demo=not args.meshes, start=start,
                             fail_on=args.fail_on)
        skipped = [result.file for result in report.meshes if result.file.skipped is not None]
        if len(inputs) == 1 and skipped:  # a report of nothing: say so, write nothing
            raise UsageError(f"{printable(skipped[0].path)}: skipped ({skipped[0].skipped}): nothing to report")
        bar.set_postfix_str("writing the page")
        collected = time.perf_counter()
        html = render_page(report)
    _write(args.output, html)
    finished = time.perf_counter()

    failed = [result.file for result in report.meshes if result.file.error is not None]
    for file in failed:
        sys.stderr.write(unreadable_line(printable(file.path), file.error, file.error_line) + "\n")
    for file in skipped:
        sys.stderr.write(f"{printable(file.path)}: skipped ({file.skipped})\n")
    if not args.quiet:
        unreadable = f", {len(failed)} unreadable" if failed else ""
        unreadable += f", {len(skipped)} skipped" if skipped else ""
        sys.stderr.write(f"affinity report: wrote {printable(args.output)} "
                         f"({len(inputs)} file{'s' * (len(inputs) != 1)}{unreadable}, "
                         f"{len(html.encode()) / 1e6:.1f} MB, {finished - start:.1f} s wall: "
                         f"{report.seconds:.1f} s collecting, {finished - collected:.1f} s writing the page)\n")
    return EXIT_ERROR if failed or skipped else EXIT_CLEAN
