"""``affinity render [MESH] -o out.png``: the hybrid render (split where affine, mvc where not).

Without MESH it draws the built-in demo scene, a lat-long sphere seen from above
the equator so that the trapezoids near the pole show the split's crease.
"""

from __future__ import annotations

import sys

from ..errors import UsageError
from . import EXIT_CLEAN, camera, image_size, pixel_tolerance, require, spelling

METHODS = ("hybrid", "split", "mvc", "bilinear", "projective", "exact")


def show_modes() -> tuple[str, ...]:
    """What ``--show`` takes (what :func:`affinity.draw.shading.shade` draws): each attribute's name, and shaded."""
    from ..attributes import ATTRIBUTES

    return (*(attribute.name for attribute in ATTRIBUTES.values()), "shaded")


def add_parser(sub) -> None:
    p = sub.add_parser(
        "render", help="render a mesh with the hybrid split/mean-value rasterizer",
        description="Render MESH (default: the built-in demo sphere) to a PNG. The hybrid's lint routing reads "
                    "the configuration governing MESH (affinity.toml or [tool.affinity], as affinity check does).",
    )
    p.add_argument("mesh", nargs="?", metavar="MESH")
    p.add_argument("-o", "--output", required=True, metavar="PNG")
    p.add_argument("--method", choices=METHODS, default="hybrid")
    p.add_argument("--route", choices=["view", "lint"], default="view",
                   help="hybrid routing: visible split error in this view (default) or the lint flags")
    p.add_argument("--pixel-tolerance", type=pixel_tolerance, default=0.5, metavar="PX",
                   help="route a quad to mvc when the split moves its texture by more than PX pixels")
    p.add_argument("--size", type=image_size, default=(800, 600), metavar="WxH")
    p.add_argument("--camera", type=camera, metavar="EX,EY,EZ,TX,TY,TZ,FOV")
    p.add_argument("--up", choices=["x", "y", "z"], default=None,
                   help="world up axis (default: the stage's upAxis for USD, else guessed from the shape: z for a "
                        "surface of revolution standing on z or a shape lying on z (a car, a terrain), else y)")
    p.add_argument("--show", choices=show_modes(), type=spelling,
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
    from ..errors import MeshError, SkippedFile
    from ..output.names import printable

    try:
        options = RenderOptions(
            method=args.method, route=args.route, pixel_tolerance=args.pixel_tolerance,
            width=args.size[0], height=args.size[1], camera=args.camera, up=args.up,
            show=args.show, texture=args.texture, overlay=args.overlay == "flags", cull=args.cull,
        )
        result = render_mesh(args.mesh, options,
                             warn=lambda line: sys.stderr.write(f"affinity render: warning: {line}\n"))
    except MeshError as err:
        raise UsageError(f"{printable(err.path)}:{err.line}: {err.reason}") from None
    except SkippedFile as skip:
        raise UsageError(f"{printable(skip.path)}: skipped ({skip.reason}): nothing to render") from None
    except (TextureError, ValueError) as err:
        raise UsageError(str(err)) from None
    try:
        from ..atomic import refuse_unsafe

        refuse_unsafe(args.output, [path for path in (args.mesh, args.texture) if path])
        result.save_png(args.output)
    except OSError as err:
        raise UsageError(f"{printable(args.output)}: cannot write ({err.strerror or err})") from None
    if not args.quiet:
        sys.stderr.write(result.summary() + f"; wrote {printable(args.output)}\n")
    return EXIT_CLEAN
