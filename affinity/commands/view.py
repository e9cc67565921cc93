"""``affinity view MESH``: the mesh in 3-D, coloured by affinity score, flagged quads outlined (pyvista).

Needs the ``view`` extra. ``--screenshot`` renders off-screen to a PNG instead
of opening a window (the report's overview picture is the same scene).
"""

from __future__ import annotations

from ..errors import MeshError, SkippedFile, UsageError
from . import EXIT_CLEAN, require, spelling


def attribute_choices() -> tuple[str, ...]:
    """The attribute names ``--attribute`` takes, from the attribute registry."""
    from ..attributes import ATTRIBUTES

    return tuple(attribute.name for attribute in ATTRIBUTES.values())


def add_parser(sub) -> None:
    p = sub.add_parser(
        "view", help="show a mesh in 3-D coloured by affinity score (needs the view extra: pyvista)",
        description="Open MESH in a window, coloured by every quad's affinity score, flagged quads outlined.",
    )
    p.add_argument("mesh", metavar="MESH")
    p.add_argument("--attribute", choices=attribute_choices(), type=spelling,
                   help="the score to colour by (default: the first the mesh has of "
                        f"{', '.join(attribute_choices())} with a flagged quad)")
    p.add_argument("--up", choices=["x", "y", "z"], help="world up axis")
    p.add_argument("--screenshot", metavar="PNG", help="render off-screen into PNG instead of opening a window")
    p.set_defaults(run=run)


def _scores(mesh, path: str, attribute: str | None):
    """The chosen attribute's scores under the file's configuration, None when the mesh has nothing to score."""
    from ..config import file_settings
    from ..lint import quad_scores, scored_codes
    from ..output.names import printable

    codes = scored_codes(mesh, attribute)  # uv, colours, normals: those the mesh has
    if not codes and attribute is not None:
        raise UsageError(f"{printable(path)}: the mesh has no {attribute} attribute to score")
    if not codes:
        return None
    settings = file_settings(path)
    scores = [quad_scores(mesh, settings, code) for code in codes[: 1 if attribute is not None else None]]
    # without --attribute, the first attribute with a flagged quad: a vertex-coloured terrain's colour findings
    # are what to see, not its clean uv
    return next((s for s in scores if (s.values > s.threshold).any()), scores[0])


def run(args) -> int:
    from ..loaders import load
    from ..output.names import printable
    from ..view import overview_image, show

    require(("pyvista",), "view")
    try:
        mesh = load(args.mesh)
    except MeshError as err:
        raise UsageError(f"{printable(err.path)}:{err.line}: {err.reason}") from None
    except SkippedFile as skip:
        raise UsageError(f"{printable(skip.path)}: skipped ({skip.reason})") from None
    scores = _scores(mesh, args.mesh, args.attribute)
    if args.screenshot is None:
        show(mesh, scores, args.up)
        return EXIT_CLEAN
    from ..draw.png import write_png

    pixels = overview_image(mesh, scores, None, args.up, (800, 600))
    try:
        write_png(args.screenshot, pixels)
    except OSError as err:
        raise UsageError(f"{printable(args.screenshot)}: cannot write ({err.strerror or err})") from None
    return EXIT_CLEAN
