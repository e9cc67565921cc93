"""Which quads need generalized barycentric coordinates in this view (the hybrid's decision).

The lint's misplacement ``m`` says how far, in attribute units, the two-triangle
split moves the attribute at a quad's centre. On screen that becomes

    error_px = m * sqrt(screen_area / attribute_area)

pixels, the quad's on-screen scale in pixels per attribute unit (design.md, "The
affinity test"). A quad goes to ``mvc`` when ``error_px`` exceeds the pixel
tolerance; everything else — affine quads, quads smaller than a pixel, quads off
screen, back-facing quads when back faces are culled — goes to ``split``. A quad
whose attributes are affine in 3-D has ``m = 0`` however it is projected, so the
rule is perspective-safe. The decision lives here, never in ``render``.
"""

from __future__ import annotations

import numpy as np

SPLIT, MVC = "split", "mvc"


def _diagonal_cross(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Signed area of quads from their corner coordinates (R, 4) each.

    The shoelace sum of a quadrilateral equals half the cross product of its
    diagonals, (p2 - p0) x (p3 - p1) / 2, for any quad (convex, concave or bow-tie).
    """
    return 0.5 * ((x[:, 2] - x[:, 0]) * (y[:, 3] - y[:, 1]) - (x[:, 3] - x[:, 1]) * (y[:, 2] - y[:, 0]))


def screen_area(clip: np.ndarray, width: int, height: int) -> np.ndarray:
    """Signed pixel area of each projected quad (counter-clockwise on screen is positive).

    Parameters
    ----------
    clip : (R, 4, 4) float64 clip-space corners (x, y, z, w)

    Returns
    -------
    (R,) float64, NaN for quads with a corner at or behind the eye (w <= 0),
    whose projection is not a bounded quad.
    """
    w = clip[..., 3]
    in_front = (w > 0).all(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        area = _diagonal_cross(clip[..., 0] / w, clip[..., 1] / w) * (0.25 * width * height)
    return np.where(in_front, area, np.nan)


def attribute_area(values: np.ndarray) -> np.ndarray:
    """Unsigned area of each quad in a 2-D attribute space, (R, 4, 2) -> (R,)."""
    return np.abs(_diagonal_cross(values[..., 0], values[..., 1]))


def on_screen(clip: np.ndarray) -> np.ndarray:
    """(R,) bool: the quad's clip-space bounds meet the view volume (conservative)."""
    x, y, z, w = (clip[..., k] for k in range(4))
    outside = ((x > w).all(1) | (x < -w).all(1) | (y > w).all(1) | (y < -w).all(1)
               | (z > w).all(1) | (w <= 0).all(1))
    return ~outside


def split_error_pixels(misplacement: np.ndarray, uv: np.ndarray, area: np.ndarray) -> np.ndarray:
    """How many pixels the split moves the texture at each quad's centre in this view.

    Parameters
    ----------
    misplacement : (R,) float64, in uv units (lint misplacement along diagonal 0-2)
    uv : (R, 4, 2) float64
    area : (R,) float64, the quads' :func:`screen_area` (NaN across the eye plane)

    Returns
    -------
    (R,) float64 pixels; ``inf`` for a disaffine quad crossing the eye plane
    (its on-screen size is unbounded) and for one with zero uv area.
    """
    area = np.where(np.isnan(area), np.inf, np.abs(area))
    with np.errstate(divide="ignore", invalid="ignore"):
        error = misplacement * np.sqrt(area / attribute_area(uv))
    return np.where(misplacement > 0, np.nan_to_num(error, nan=np.inf), 0.0)


def route_by_view(
    misplacement: np.ndarray,
    uv: np.ndarray,
    clip: np.ndarray,
    width: int,
    height: int,
    pixel_tolerance: float = 0.5,
    cull_back_faces: bool = False,
) -> np.ndarray:
    """Per-quad method for the hybrid render: ``"mvc"`` where the split error is visible.

    Returns
    -------
    (R,) array of str, ``"split"`` or ``"mvc"``.
    """
    area = screen_area(clip, width, height)
    visible = on_screen(clip) & ~(np.abs(area) < 1.0)
    if cull_back_faces:
        visible &= ~(area < 0)
    needs = visible & (split_error_pixels(misplacement, uv, area) > pixel_tolerance)
    return np.where(needs, MVC, SPLIT)
