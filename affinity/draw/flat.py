"""Flat drawings: quads given in 2-D picture coordinates, as the texture-space layout draws them.

The quads are rasterized by the project's renderer with an orthographic view
(x, y in [-1, 1], y up), so a drawing of a million quads costs one render.
"""

from __future__ import annotations

import numpy as np


def face_ids(points: np.ndarray, nearer: np.ndarray, size: int) -> np.ndarray:
    """Which quad covers each pixel of a ``size`` x ``size`` picture.

    Parameters
    ----------
    points : (R, 4, 2) float64
        Each quad's corners in [-1, 1]^2 (x right, y up), in outline order.
    nearer : (R,) bool
        Quads drawn over the others where quads overlap; among equals the earlier wins.
    size : int
        The picture's side, pixels.

    Returns
    -------
    (size, size) int64: the quad covering each pixel (row 0 at the top), -1 where none does.
    """
    from render import rasterize_quads

    depth = np.repeat(np.where(nearer, -0.5, 0.0)[:, None, None], 4, axis=1)
    clip = np.concatenate([points, depth, np.ones(points.shape[:2] + (1,))], axis=-1)
    return rasterize_quads(clip, np.zeros(points.shape[:2] + (0,)), size, size, method="split").face
