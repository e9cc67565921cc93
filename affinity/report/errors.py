"""Per-pixel attribute error of a render against the exact reference, in the lint's units.

The same units as the affinity rules: texels for uv (Q101), 1/255 steps for
colours (Q102), degrees for normals (Q103).
"""

from __future__ import annotations

import numpy as np

from ..measures import color_steps, texels


def pixel_error(values: np.ndarray, reference: np.ndarray, code: str, texture_size) -> np.ndarray:
    """Error of interpolated attributes against the reference's.

    Parameters
    ----------
    values, reference : (N, K) float64, the attribute at N pixels
    code : the rule whose unit to use, ``"Q101"``, ``"Q102"`` or ``"Q103"``
    texture_size : (width, height) in texels, for Q101

    Returns
    -------
    (N,) float64: |du, dv| in texels, |d rgb| in 1/255 steps, or the angle
    between the two normals in degrees.
    """
    if code == "Q101":
        return texels(values - reference, texture_size)
    if code == "Q102":
        return color_steps(values - reference)
    cross = np.linalg.norm(np.cross(values, reference), axis=-1)
    return np.degrees(np.arctan2(cross, np.einsum("nk,nk->n", values, reference)))
