"""Numerical stability of this scene: the drawn pixels where a quad's coordinates are worst conditioned.

The hybrid evaluates mean value coordinates (HT04 eq. 7, 8, 10) at the pixels of
the quads it sends to mvc. Every such pixel is screened by evaluating
``render.coords.mean_value`` there in float64 and in float32 (the inputs
rounded to float32); the pixels where the two disagree most are the candidates
(needles, near-degenerate quads, poles, corners nearly behind the eye). For
the worst few, the mpmath reference (``affinity.stability.reference``) and the
condition estimate (``affinity.stability.condition``) decide: a pixel is stiff
when the condition number exceeds ``STIFF_CONDITION`` or an error exceeds the
tolerance its condition allows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Pixels checked against mpmath, the worst by the float32 screen first (each on a different quad).
CANDIDATES = 6
#: A condition number (relative change of the result per relative change of the inputs) above this is stiff.
STIFF_CONDITION = 1e6


@dataclass
class StiffPixel:
    """One checked pixel: its mesh face, pixel (row, col), condition number, and errors against mpmath with the
    tolerances they are held to (float64 and float32)."""

    face: int
    pixel: tuple[int, int]
    condition: float
    error64: float
    tolerance64: float
    error32: float
    tolerance32: float

    @property
    def stiff(self) -> bool:
        return (self.condition > STIFF_CONDITION or self.error64 > self.tolerance64
                or self.error32 > self.tolerance32)


@dataclass
class SceneStability:
    """The screen's result: how many mvc pixels were screened, and the checked pixels, worst first."""

    screened: int
    checked: list[StiffPixel]

    @property
    def stiff(self) -> list[StiffPixel]:
        return [pixel for pixel in self.checked if pixel.stiff]


def _screen_quads(render):
    """Screen corners (R, 4, 2) in NDC and w (R, 4) of the render quads, as the renderer saw them."""
    w = render.clip[..., 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        return render.clip[..., :2] / w[..., None], w


def _max_error(values, reference) -> float:
    return float(np.max(np.abs(np.asarray(values, dtype=np.float64) - np.asarray(reference, dtype=np.float64))))


def _check(p: np.ndarray, quad: np.ndarray, w: np.ndarray, face: int, pixel) -> StiffPixel | None:
    """mpmath reference and condition at one pixel; None where the weights are undefined there."""
    from render.coords import mean_value

    from ..stability.condition import condition, tolerance
    from ..stability.reference import Undefined, homogeneous, mean_value_exact, offsets
    from ..stability.rows import UNIT_ROUNDOFF

    results = {}
    for precision in ("float64", "float32"):
        dtype = np.dtype(precision)
        p_, quad_, w_ = p.astype(dtype), quad.astype(dtype), w.astype(dtype)
        s, hw = offsets(p_, quad_), homogeneous(w_)
        u = UNIT_ROUNDOFF[precision]
        try:
            exact = [float(v) for v in mean_value_exact(s, hw)]
            cond = condition(mean_value_exact, s, hw, u)
        except Undefined:
            return None
        value = mean_value(p_[None], quad_, w_)[0]
        results[precision] = (_max_error(value, exact), tolerance(cond, u), cond / u)
    (e64, t64, kappa), (e32, t32, _) = results["float64"], results["float32"]
    return StiffPixel(face, pixel, kappa, e64, t64, e32, t32)


def render_stability(render) -> SceneStability:
    """Screen the mvc pixels of ``render`` (the hybrid's RenderResult) and check the worst against mpmath."""
    from render.coords import mean_value

    face = render.frame.face
    rows, cols = np.nonzero(render.mvc_pixels)
    if len(rows) == 0:
        return SceneStability(0, [])
    ndc, w = _screen_quads(render)
    quads = face[rows, cols]
    # a quad whose w leaves float32's range (coordinates near 1e38 and up) has no float32 render to compare
    keep = (w[quads] > 0).all(axis=1) & (w[quads] < np.finfo(np.float32).max).all(axis=1)
    rows, cols, quads = rows[keep], cols[keep], quads[keep]
    height, width = face.shape
    p = np.stack([(cols + 0.5) * 2 / width - 1, 1 - (rows + 0.5) * 2 / height], axis=1)
    with np.errstate(all="ignore"):
        wide = mean_value(p, ndc[quads], w[quads])
        narrow = mean_value(p.astype(np.float32), ndc[quads].astype(np.float32), w[quads].astype(np.float32))
    disagreement = np.nan_to_num(np.abs(wide - narrow).max(axis=1), nan=np.inf)
    order = np.argsort(-disagreement, kind="stable")
    _, first = np.unique(quads[order], return_index=True)  # the worst pixel of each quad, as a rank in ``order``
    worst = order[np.sort(first)]
    checked = []
    for k in worst[:CANDIDATES]:
        result = _check(p[k], ndc[quads[k]], w[quads[k]], int(render.faces[quads[k]]), (int(rows[k]), int(cols[k])))
        if result is not None:
            checked.append(result)
    checked.sort(key=lambda r: -max(r.condition / STIFF_CONDITION, r.error32 / r.tolerance32,
                                    r.error64 / r.tolerance64))
    return SceneStability(len(rows), checked)
