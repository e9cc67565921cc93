"""Which quads need generalized barycentric coordinates in this view (the hybrid's decision).

The split moves the texture on the surface. Swap the roles of the lint's test
(``affinity.measures``): the uv quad is the domain, its split along 0-2 carries
the positions affinely, and the exact render shows the bilinear positions P(s, t)
over it. A texture feature at uv u is drawn at x_split(u) instead of x_exact(u),
and the same derivation gives

    x_split - x_exact = (1-s) t R_p / T_3  or  s (1-t) R_p / T_1,
    R_p = sum_k (-1)^k T_k p_k,

with T_k the doubled signed areas of the uv quad's triangles: a 3-D vector of
fixed direction R_p, largest at (s*, t*) = (sqrt T_1, sqrt T_3) / (sqrt T_1 +
sqrt T_3), where it is D = R_p / (sqrt T_1 + sqrt T_3)^2. Both D and the point
P(s*, t*) are fixed combinations of the quad's corners (``UvDisplacement``, once
per mesh), so in a view their clip-space images are the same combinations of
the clip-space corners, and the screen displacement is the camera's Jacobian at
P(s*, t*) applied to D:

    d_ndc = (dX W - X dW) / W^2  (and y alike),  pixels = |d_ndc * (width, height) / 2|.

A quad goes to ``mvc`` when that exceeds the pixel tolerance, and also when

- its uv triangles have opposite orientation (a fold, e.g. at a wrapped seam),
- it is disaffine and a corner lies at or behind the near plane;

a quad whose uv quad is degenerate (Q301, at its configured threshold) has no displacement and is routed by
the lint's uv error times its screen scale. Everything else -- affine quads,
quads smaller than a pixel, quads off screen, back-facing quads when back faces
are culled -- goes to ``split``. The decision lives here, never in ``render``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import planar_quads, relative_signed_area
from ..measures import split_error_point
from ..rules import RULES
from ..rules.texture import UV_DEGENERATE

SPLIT, MVC = "split", "mvc"

#: A displacement below this fraction of the quad's clip-space extent is rounding: the quad is affine.
AFFINE_DISPLACEMENT = 1e-9


@dataclass(frozen=True)
class UvDisplacement:
    """The view-independent part of the routing, per render quad (R quads).

    Attributes
    ----------
    weights : (R, 4) float64
        D = sum_k weights_k p_k is the texture's largest on-surface displacement
        (weights sum to 0, so any affine image of the corners maps D alike).
    at : (R, 4) float64
        Bilinear weights of the point P(s*, t*) where it is largest.
    folded : (R,) bool
        The uv triangles (0, 2, 3) and (0, 1, 2) have opposite orientation.
    degenerate : (R,) bool
        The uv quad is degenerate (Q301 at the threshold given to ``uv_displacement``).
    """

    weights: np.ndarray
    at: np.ndarray
    folded: np.ndarray
    degenerate: np.ndarray


def uv_displacement(uv: np.ndarray, degenerate_at: float = RULES[UV_DEGENERATE].default_threshold) -> UvDisplacement:
    """Corner weights of the split's largest texture displacement along diagonal 0-2.

    Parameters
    ----------
    uv : (R, 4, 2) float64 texture coordinates of the render quads.
    degenerate_at : Q301's threshold: a uv quad whose relative area is at or below it is degenerate
        (``Settings.threshold("Q301")``; the rule's default when not given).
    """
    quads = planar_quads(uv)
    # A mirrored uv quad (clockwise) is measured as its mirror image.
    T = quads.areas * np.where(quads.areas[:, 1] + quads.areas[:, 3] < 0, -1.0, 1.0)[:, None]
    tolerance = quads.tolerance
    folded = (T[:, 1] < -tolerance) | (T[:, 3] < -tolerance)
    degenerate = np.abs(relative_signed_area(quads)) <= degenerate_at
    s, t = split_error_point(T[:, 1], T[:, 3])
    at = np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t], axis=1)
    root = np.sqrt(np.maximum(T[:, 1], 0)) + np.sqrt(np.maximum(T[:, 3], 0))
    scale = np.divide(1.0, root * root, out=np.zeros_like(root), where=~degenerate & (root > 0))
    weights = T * np.array([1.0, -1.0, 1.0, -1.0]) * scale[:, None]
    return UvDisplacement(weights, at, folded, degenerate)


def clip_components(clip: np.ndarray) -> np.ndarray:
    """(R, 4, 4) clip corners -> (4, 4, R) contiguous: [component, corner], the layout the functions below
    take, so that the per-quad arithmetic runs on contiguous rows (several times faster than on the
    interleaved layout). Convert once per frame."""
    return np.ascontiguousarray(np.transpose(clip, (2, 1, 0)))


def screen_area(c: np.ndarray, width: int, height: int) -> np.ndarray:
    """Signed pixel area of each projected quad (counter-clockwise on screen is positive).

    The shoelace sum of a quadrilateral equals half the cross product of its
    diagonals, (p2 - p0) x (p3 - p1) / 2, for any quad (convex, concave or bow-tie).

    Parameters
    ----------
    c : (4, 4, R) float64 clip-space corners by component (``clip_components``)

    Returns
    -------
    (R,) float64, NaN for quads with a corner at or behind the eye (w <= 0),
    whose projection is not a bounded quad.
    """
    w = c[3]
    with np.errstate(divide="ignore", invalid="ignore"):
        x, y = c[0] / w, c[1] / w
        area = ((x[2] - x[0]) * (y[3] - y[1]) - (x[3] - x[1]) * (y[2] - y[0])) * (0.125 * width * height)
    return np.where((w > 0).all(axis=0), area, np.nan)


def on_screen(c: np.ndarray) -> np.ndarray:
    """(R,) bool: the quad's clip-space bounds meet the view volume (conservative); ``c`` as in
    :func:`screen_area`."""
    x, y, z, w = c
    outside = ((x > w).all(0) | (x < -w).all(0) | (y > w).all(0) | (y < -w).all(0)
               | (z > w).all(0) | (w <= 0).all(0))
    return ~outside


def _combine(weights: np.ndarray, c: np.ndarray) -> np.ndarray:
    """sum_k weights[:, k] c[:, k]: (R, 4) weights of the corners of (4, 4, R) -> (4, R)."""
    total = c[:, 0] * weights[:, 0]
    for k in range(1, 4):
        total += c[:, k] * weights[:, k]
    return total


def displacement_pixels(moves: UvDisplacement, c: np.ndarray, width: int, height: int) -> np.ndarray:
    """The split's largest texture displacement on screen, in pixels.

    Parameters
    ----------
    moves : UvDisplacement of R quads
    c : (4, 4, R) float64 clip-space corners by component (``clip_components``)

    Returns
    -------
    (R,) float64; ``inf`` for a disaffine quad with a corner at or behind the
    near plane (z < -w, or w <= 0), 0 for an affine one (a displacement below
    ``AFFINE_DISPLACEMENT`` times the largest clip coordinate).
    """
    X, Y, _, W = _combine(moves.at, c)
    d = _combine(moves.weights, c)
    with np.errstate(divide="ignore", invalid="ignore"):
        dx = (d[0] * W - X * d[3]) / (W * W) * (0.5 * width)
        dy = (d[1] * W - Y * d[3]) / (W * W) * (0.5 * height)
        pixels = np.hypot(dx, dy)
    extent = np.abs(c).max(axis=(0, 1))
    affine = np.abs(d).max(axis=0) <= AFFINE_DISPLACEMENT * extent
    near = ((c[2] < -c[3]) | (c[3] <= 0)).any(axis=0)
    pixels = np.where(near, np.inf, np.nan_to_num(pixels, nan=np.inf))
    return np.where(affine, 0.0, pixels)


def degenerate_uv_pixels(uv_error: np.ndarray, uv: np.ndarray, area: np.ndarray) -> np.ndarray:
    """Pixels for quads whose uv quad is degenerate: the lint's uv error times the
    screen scale sqrt(|screen area|) / (longest uv edge), pixels per uv unit.

    uv_error : (R,) float64 in uv units; uv : (R, 4, 2); area : (R,) ``screen_area``
    (NaN across the eye plane, which gives ``inf`` for a nonzero error).
    """
    edge = np.sqrt(((np.roll(uv, -1, axis=1) - uv) ** 2).sum(axis=2)).max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        error = uv_error * np.sqrt(np.abs(area)) / edge
    return np.where(uv_error > 0, np.nan_to_num(error, nan=np.inf), 0.0)


def route_by_view(
    moves: UvDisplacement,
    uv: np.ndarray,
    clip: np.ndarray,
    width: int,
    height: int,
    pixel_tolerance: float = 0.5,
    cull_backfaces: bool = False,
    uv_error: np.ndarray | None = None,
) -> np.ndarray:
    """Per-quad method for the hybrid render: ``"mvc"`` where the split's texture displacement shows.

    Parameters
    ----------
    moves : ``uv_displacement(uv)``
    uv : (R, 4, 2) float64
    clip : (R, 4, 4) float64
    uv_error : (R,) float64, the lint's uv error (uv units, diagonal 0-2) of each
        quad, read for the quads whose uv quad is degenerate; None: they stay split.

    Returns
    -------
    (R,) array of str, ``"split"`` or ``"mvc"``.
    """
    c = clip_components(clip)
    area = screen_area(c, width, height)
    visible = on_screen(c) & ~(np.abs(area) < 1.0)
    if cull_backfaces:
        visible &= ~(area < 0)
    pixels = displacement_pixels(moves, c, width, height)
    if moves.degenerate.any():
        rows = np.flatnonzero(moves.degenerate)
        pixels[rows] = 0.0 if uv_error is None else degenerate_uv_pixels(uv_error[rows], uv[rows], area[rows])
    needs = visible & ((pixels > pixel_tolerance) | moves.folded)
    return np.where(needs, MVC, SPLIT)
