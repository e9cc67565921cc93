"""Charts as inline SVG, drawn with matplotlib (no display, no fonts fetched).

Text stays text (``svg.fonttype = none``) and one SVG unit is one CSS pixel at
the chart's own width, so a font size here is the size the reader sees; the
page never shows a chart narrower than that width (the smallest text is 12 px).
"""

from __future__ import annotations

import io
import re

import numpy as np

from ..draw import FLAG_COLOUR

PASS_COLOUR = "#5b7fa6"
#: Values spanning more than this ratio get a logarithmic x axis.
LOG_SPAN = 100.0


TEXT_PX = 12
#: SVG output is in points: 72 per inch, one point per CSS pixel once the size attributes say px.
POINTS = 72


def _figure(width_px: int, height_px: int):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width_px / POINTS, height_px / POINTS), dpi=POINTS)
    axes = figure.add_subplot()
    axes.spines[["top", "right"]].set_visible(False)
    axes.tick_params(labelsize=TEXT_PX)
    axes.grid(axis="y", color="#e5e7eb", linewidth=0.8)
    axes.set_axisbelow(True)
    return figure, axes


def svg_markup(figure) -> str:
    """The figure as an ``<svg>`` element for inline use: text as text, sized in px, no XML prologue."""
    import matplotlib

    out = io.StringIO()
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "affinity"}):
        figure.savefig(out, format="svg", metadata={"Date": None, "Creator": None})
    text = out.getvalue()
    text = text[text.index("<svg"):]
    # Inline in HTML, the SVG needs no namespace declarations (the parser knows svg and xlink:href) nor the
    # RDF metadata; both would only put URLs into a page that references nothing outside itself.
    text = re.sub(r"<metadata>.*?</metadata>\s*", "", text, flags=re.DOTALL)
    text = re.sub(r'\s+xmlns(:\w+)?="[^"]*"', "", text)
    text = re.sub(r'(<svg[^>]*?) width="([\d.]+)pt" height="([\d.]+)pt"', r'\1 width="\2" height="\3" class="chart"',
                  text, count=1)
    return text


def score_histogram(values: np.ndarray, threshold: float, floor: float, unit: str, title: str) -> str:
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

    figure, axes = _figure(520, 270)
    axes.hist([clamped[~flagged], clamped[flagged]], bins=edges, stacked=True,
              color=[PASS_COLOUR, FLAG_COLOUR], label=["passes", "flagged"])
    if log:  # plain numbers at each decade: matplotlib's 10^k labels go through mathtext, 0.5 s a chart
        axes.set_xscale("log")
        _plain_log(axes.xaxis, subs=(1.0,))
    axes.axvline(threshold, color="#111827", linestyle="--", linewidth=1.2)
    axes.set_xlabel(f"{unit} (dashed: threshold {threshold:g})", fontsize=TEXT_PX)
    axes.set_ylabel("quads", fontsize=TEXT_PX)
    axes.set_title(title, fontsize=TEXT_PX + 1, loc="left", pad=22)
    # The legend sits above the plotting area, in one row, so it never covers a bar.
    axes.legend(fontsize=TEXT_PX, frameon=False, loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=2,
                borderaxespad=0.0, handlelength=1.2)
    figure.tight_layout()
    return svg_markup(figure)


#: Methods of the study chart, with their colours.
STUDY_METHODS = {"split": "#c2410c", "mvc": "#1d4ed8", "bilinear": "#15803d", "projective": "#7e22ce",
                 "exact": "#111827"}
HYBRID_COLOUR = "#db2777"


def _plain_log(axis, subs) -> None:
    """Label a log axis with plain numbers at ``subs`` times each decade, and no minor labels."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axis.set_major_locator(LogLocator(base=10, subs=subs, numticks=6))
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axis.set_minor_formatter(NullFormatter())


def study_chart(rows: list[dict], scenes: list[str]) -> str:
    """Error against run time from the committed study, one panel per scene (2 columns), as inline SVG.

    ``rows`` are the study table's rows (``affinity/data/study/study.csv`` read as
    dicts of strings). Each method is its median time over the study's repeats
    with a bar from the fastest to the slowest repeat; the hybrid (routed by the
    view) is a line over its pixel tolerances. Errors of 0 are drawn at 1e-4.
    The legend is below the panels, never over them.
    """
    import math

    columns = 2
    panel_rows = math.ceil(len(scenes) / columns)
    figure, _ = _figure(340 * columns, 250 * panel_rows + 60)
    figure.clear()
    axes = figure.subplots(panel_rows, columns, squeeze=False).ravel()
    for extra in axes[len(scenes):]:
        extra.set_visible(False)
    for ax, scene in zip(axes, scenes):
        of_scene = [row for row in rows if row["scene"] == scene]
        hybrid = sorted((r for r in of_scene if r["route"] == "view"), key=lambda r: float(r["setting"]))
        ax.plot([float(r["seconds"]) * 1e3 for r in hybrid], [max(float(r["err_rms"]), 1e-4) for r in hybrid],
                "-o", color=HYBRID_COLOUR, markersize=3, linewidth=1.2, label="hybrid (pixel tolerance 0.03-8)")
        for row in of_scene:
            if row["method"] in STUDY_METHODS and not row["route"]:
                t, low, high = (float(row[k]) * 1e3 for k in ("seconds", "seconds_min", "seconds_max"))
                ax.errorbar([t], [max(float(row["err_rms"]), 1e-4)], xerr=[[t - low], [high - t]], fmt="s",
                            color=STUDY_METHODS[row["method"]], markersize=5, capsize=2, label=row["method"])
        ax.set_xscale("log")
        ax.set_yscale("log")
        _plain_log(ax.xaxis, (1.0, 2.0, 5.0))
        _plain_log(ax.yaxis, (1.0,))
        ax.set_title(scene, fontsize=TEXT_PX, loc="left")
        ax.set_xlabel("time (ms), median of repeats", fontsize=TEXT_PX)
        ax.set_ylabel(f"RMS error ({of_scene[0]['unit']})", fontsize=TEXT_PX)
        ax.tick_params(labelsize=TEXT_PX)
        ax.spines[["top", "right"]].set_visible(False)
    handles = dict(zip(*reversed(axes[0].get_legend_handles_labels())))
    figure.legend(list(handles.values()), list(handles.keys()), loc="lower center", ncol=3, fontsize=TEXT_PX,
                  frameon=False)
    figure.tight_layout(rect=(0, 60 / (250 * panel_rows + 60), 1, 1))
    return svg_markup(figure)
