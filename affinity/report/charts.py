"""Charts as PNG bytes, drawn with matplotlib's Agg backend (no display, no fonts fetched)."""

from __future__ import annotations

import io

import numpy as np

from ..draw.shading import FLAG_COLOUR

PASS_COLOUR = "#5b7fa6"
#: Values spanning more than this ratio get a logarithmic x axis.
LOG_SPAN = 100.0


def _figure(width_px: int, height_px: int, dpi: int = 110):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width_px / dpi, height_px / dpi), dpi=dpi)
    axes = figure.add_subplot()
    axes.spines[["top", "right"]].set_visible(False)
    axes.tick_params(labelsize=8)
    axes.grid(axis="y", color="#e5e7eb", linewidth=0.8)
    axes.set_axisbelow(True)
    return figure, axes


def _png(figure) -> bytes:
    out = io.BytesIO()
    figure.savefig(out, format="png", metadata={"Software": None})
    return out.getvalue()


def score_histogram(values: np.ndarray, threshold: float, floor: float, unit: str, title: str) -> bytes:
    """Histogram of affinity scores with the threshold marked; flagged quads in the flag colour.

    Parameters
    ----------
    values : (n,) float64, finite or +inf, the scores of every measured quad
    threshold : the rule flags values above it
    floor : values below it are drawn in the first bin (a log axis cannot show 0)
    unit, title : axis label unit and chart title

    The x axis is logarithmic when the values span more than ``LOG_SPAN``;
    infinite scores are drawn in the last bin.
    """
    finite_max = float(np.max(values[np.isfinite(values)], initial=floor))
    top = max(finite_max, threshold) * 1.05
    low = min(max(float(np.min(values)), floor), threshold)
    log = top / low > LOG_SPAN
    edges = np.geomspace(low, top, 31) if log else np.linspace(0.0, top, 31)  # scores are >= 0
    clamped = np.clip(values, edges[0], edges[-1])
    flagged = values > threshold

    figure, axes = _figure(560, 250)
    axes.hist([clamped[~flagged], clamped[flagged]], bins=edges, stacked=True,
              color=[PASS_COLOUR, FLAG_COLOUR], label=["passes", "flagged"])
    if log:
        axes.set_xscale("log")
    axes.axvline(threshold, color="#111827", linestyle="--", linewidth=1.2)
    axes.annotate(f"threshold {threshold:g}", (threshold, 1.0), xycoords=("data", "axes fraction"),
                  xytext=(4, -2), textcoords="offset points", fontsize=8, va="top")
    axes.set_xlabel(unit, fontsize=9)
    axes.set_ylabel("quads", fontsize=9)
    axes.set_title(title, fontsize=10, loc="left")
    axes.legend(fontsize=8, frameon=False, loc="upper center")
    figure.tight_layout()
    return _png(figure)
