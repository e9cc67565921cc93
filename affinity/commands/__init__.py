"""One module per subcommand: each has ``add_parser(subparsers)`` and ``run(args) -> exit code``.

Subcommands import what they need inside ``run``, so ``affinity check`` pays
for NumPy and nothing heavier.
"""

import argparse
import math

EXIT_CLEAN, EXIT_FINDINGS, EXIT_ERROR = 0, 1, 2


def spelling(text: str) -> str:
    """An argparse ``type`` for attribute names: each attribute's own name (``color``) everywhere,
    its aliases (``colour``) accepted (:data:`affinity.attributes.ATTRIBUTES`)."""
    from ..attributes import canonical_name

    return canonical_name(text)


def require(modules: tuple[str, ...], extra: str) -> None:
    """Stop with one line naming the missing modules and the extra that installs them.

    Raises ``affinity.errors.UsageError`` (exit 2) instead of an ImportError traceback.
    """
    import importlib.util

    from ..errors import UsageError

    missing = [name for name in modules if importlib.util.find_spec(name) is None]
    if missing:
        raise UsageError(f"needs {', '.join(missing)}, the {extra} extra: pip install 'quad-affinity[{extra}]'")


def image_size(text: str) -> tuple[int, int]:
    """An argparse ``type``: ``"800x600"`` -> (800, 600)."""
    width, _, height = text.lower().partition("x")
    try:
        size = int(width), int(height)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an image size: {text!r} (use e.g. 800x600)") from None
    if min(size) < 1:
        raise argparse.ArgumentTypeError(f"image size must be at least 1x1, got {text!r}")
    return size


def camera(text: str) -> tuple[tuple[float, ...], tuple[float, ...], float]:
    """An argparse ``type``: ``"EX,EY,EZ,TX,TY,TZ,FOV"`` -> ((ex, ey, ez), (tx, ty, tz), fov)."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 7 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError("use --camera EX,EY,EZ,TX,TY,TZ,FOV (eye, target, vertical fov in degrees)")
    if not 0 < values[6] < 180:
        raise argparse.ArgumentTypeError(f"the field of view must lie between 0 and 180 degrees, got {values[6]:g}")
    return tuple(values[:3]), tuple(values[3:6]), values[6]


def pixel_tolerance(text: str) -> float:
    """An argparse ``type`` for ``--pixel-tolerance``: a number of pixels, zero or more (NaN would route nothing)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"not a pixel tolerance: {text!r} (a number of pixels, 0 or more)")
    return value
