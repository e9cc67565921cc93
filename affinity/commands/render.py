"""``affinity render [MESH] -o out.png``: the hybrid render (split where affine, mvc where not).

Without MESH it draws the built-in demo scene, a lat-long sphere seen from above
the equator so that the trapezoids near the pole show the split's crease.
"""

from __future__ import annotations

import argparse
import math
import sys

from ..errors import UsageError
from . import EXIT_CLEAN, require, spelling

METHODS = ("hybrid", "split", "mvc", "bilinear", "projective", "exact")
SHOW_MODES = ("uv", "color", "normal", "shaded")  # what affinity.draw.shading.shade draws


def _size(text: str) -> tuple[int, int]:
    width, _, height = text.lower().partition("x")
    try:
        size = int(width), int(height)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an image size: {text!r} (use e.g. 800x600)") from None
    if min(size) < 1:
        raise argparse.ArgumentTypeError(f"image size must be at least 1x1, got {text!r}")
    return size


def _camera(text: str) -> tuple[tuple[float, ...], tuple[float, ...], float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 7 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError("use --camera EX,EY,EZ,TX,TY,TZ,FOV (eye, target, vertical fov in degrees)")
    if not 0 < values[6] < 180:
        raise argparse.ArgumentTypeError(f"the field of view must lie between 0 and 180 degrees, got {values[6]:g}")
    return tuple(values[:3]), tuple(values[3:6]), values[6]


def _tolerance(text: str) -> float:
    """``--pixel-tolerance``: a number of pixels, zero or more (NaN would route nothing)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"not a pixel tolerance: {text!r} (a number of pixels, 0 or more)")
    return value


def add_parser(sub) -> None:
    p = sub.add_parser(
        "render", help="render a mesh with the hybrid split/mean-value rasterizer",
        description="Render MESH (default: the built-in demo sphere) to a PNG.",
    )
    p.add_argument("mesh", nargs="?", metavar="MESH")
    p.add_argument("-o", "--output", required=True, metavar="PNG")
    p.add_argument("--method", choices=METHODS, default="hybrid")
    p.add_argument("--route", choices=["view", "lint"], default="view",
                   help="hybrid routing: visible split error in this view (default) or the lint flags")
    p.add_argument("--pixel-tolerance", type=_tolerance, default=0.5, metavar="PX",
                   help="route a quad to mvc when the split moves its texture by more than PX pixels")
    p.add_argument("--size", type=_size, default=(800, 600), metavar="WxH")
    p.add_argument("--camera", type=_camera, metavar="EX,EY,EZ,TX,TY,TZ,FOV")
    p.add_argument("--up", choices=["x", "y", "z"], default=None, help="world up axis (default: the stage's upAxis for USD, else y; z for the demo)")
    p.add_argument("--show", choices=SHOW_MODES, type=spelling,
                   help="what to draw (default: uv when the mesh has it, else color, else shaded)")
    p.add_argument("--texture", metavar="IMAGE", help="texture image for uv (default: map_Kd, else a checker)")
    p.add_argument("--overlay", choices=["flags"], help="tint the quads sent to mvc")
    p.add_argument("--cull", action="store_true", help="cull back faces")
    p.add_argument("-q", "--quiet", action="store_true", help="do not print where the quads went")
    p.set_defaults(run=run)


def run(args) -> int:
    require(("PIL",), "render")
    from ..draw import RenderOptions, render_mesh
    from ..draw.texture import TextureError
    from ..errors import MeshError

    try:
        options = RenderOptions(
            method=args.method, route=args.route, pixel_tolerance=args.pixel_tolerance,
            width=args.size[0], height=args.size[1], camera=args.camera, up=args.up,
            show=args.show, texture=args.texture, overlay=args.overlay == "flags", cull=args.cull,
        )
        result = render_mesh(args.mesh, options, warn=lambda line: sys.stderr.write(f"affinity render: warning: {line}\n"))
    except MeshError as err:
        raise UsageError(f"{err.path}:{err.line}: {err.reason}") from None
    except (TextureError, ValueError) as err:
        raise UsageError(str(err)) from None
    try:
        result.save_png(args.output)
    except OSError as err:
        raise UsageError(f"{args.output}: cannot write ({err.strerror or err})") from None
    if not args.quiet:
        sys.stderr.write(result.summary() + f"; wrote {args.output}\n")
    return EXIT_CLEAN
