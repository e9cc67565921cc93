"""The study's charts as PNG bytes (matplotlib, Agg backend).

- :func:`error_against_time` — one panel per scene: RMS error against exact over
  median run time, log-log, one point per method and per hybrid setting, the
  Pareto front as a step line, exact's time as a dotted line.
- :func:`hybrid_sweep` — one panel per scene: for each hybrid route, the share
  of quads sent to mvc against the error (and, right axis, the time).
- :func:`relative_cost` — every scene in one chart: time and error of each
  method and of the default hybrid, relative to the split.
"""

from __future__ import annotations

import io
import math

import numpy as np

from .tables import error_label, headline_hybrid

#: Errors below this are drawn at it (a log axis has no zero): "no error" to plotting precision.
ERROR_FLOOR = 1e-4
METHOD_STYLE = {  # method: (colour, marker)
    "split": ("#c2410c", "s"),
    "split-13": ("#fb923c", "s"),
    "mvc": ("#1d4ed8", "o"),
    "bilinear": ("#15803d", "^"),
    "projective": ("#7e22ce", "D"),
    "exact": ("#111827", "*"),
}
ROUTE_STYLE = {"view": "#db2777", "lint error": "#0891b2", "lint barycentric": "#ca8a04"}
PANEL = (3.4, 2.7)  # inches per panel
COLUMNS = 3


def _grid(count: int):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    rows = max(1, math.ceil(count / COLUMNS))
    columns = min(COLUMNS, max(count, 1))
    figure = Figure(figsize=(PANEL[0] * columns, PANEL[1] * rows + 0.6), dpi=100)
    axes = figure.subplots(rows, columns, squeeze=False).ravel()
    for extra in axes[count:]:
        extra.set_visible(False)
    return figure, axes[:count]


def _png(figure) -> bytes:
    out = io.BytesIO()
    figure.savefig(out, format="png", metadata={"Software": None})
    return out.getvalue()


def _plain_log(axis) -> None:
    """A log axis (already holding its data) labelled with plain numbers: 1, 2, 5 per decade
    over at most three decades, else the decades only; no minor labels."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    low, high = axis.get_view_interval()
    subs = (1.0, 2.0, 5.0) if high <= 1e3 * low else (1.0,)
    axis.set_major_locator(LogLocator(base=10, subs=subs, numticks=8))
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axis.set_minor_formatter(NullFormatter())


def _scenes(rows: list[dict]) -> list[str]:
    return list(dict.fromkeys(row["scene"] for row in rows))


def _floored(values) -> np.ndarray:
    return np.maximum(np.asarray(values, dtype=np.float64), ERROR_FLOOR)


def error_against_time(rows: list[dict], time_label: str = "median time (ms)") -> bytes:
    """Error (log) against run time (log), one panel per scene; exact (no error) as a line at its time."""
    scenes = _scenes(rows)
    figure, axes = _grid(len(scenes))
    for ax, scene in zip(axes, scenes):
        of_scene = [row for row in rows if row["scene"] == scene]
        for route, colour in ROUTE_STYLE.items():
            sweep = sorted((row for row in of_scene if row["route"] == route), key=lambda row: row["setting"])
            if sweep:
                ax.plot([r["seconds"] * 1e3 for r in sweep], _floored([r["err_rms"] for r in sweep]), "-",
                        color=colour, marker=".", markersize=5, linewidth=1, label=f"hybrid, {route}")
        for row in of_scene:
            if row["method"] == "exact":
                ax.axvline(row["seconds"] * 1e3, color=METHOD_STYLE["exact"][0], linestyle=":", linewidth=1,
                           label="exact (the reference): its time")
            elif not row["route"]:
                colour, marker = METHOD_STYLE[row["method"]]
                ax.plot(row["seconds"] * 1e3, _floored(row["err_rms"]), marker, color=colour, label=row["method"],
                        markersize=6, linestyle="none")
        front = sorted((row for row in of_scene if row["pareto"]), key=lambda row: row["seconds"])
        ax.step([r["seconds"] * 1e3 for r in front], _floored([r["err_rms"] for r in front]), where="post",
                color="#6b7280", linewidth=0.8, linestyle="--", label="Pareto front")
        ax.set_xscale("log")
        ax.set_yscale("log")
        _plain_log(ax.xaxis)
        _plain_log(ax.yaxis)
        ax.set_title(scene, fontsize=9, loc="left")
        ax.set_xlabel(time_label, fontsize=8)
        ax.set_ylabel(error_label(of_scene[0]["unit"]), fontsize=8)
        ax.tick_params(labelsize=7)
    _legend(figure, axes)
    figure.suptitle(f"Error against exact vs run time (errors below {ERROR_FLOOR:g} drawn at it)", fontsize=10)
    figure.tight_layout(rect=(0, 0.05, 1, 0.97))
    return _png(figure)


def hybrid_sweep(rows: list[dict]) -> bytes:
    """Share of quads sent to mvc against error (left, log) and time (right), one panel per scene."""
    scenes = [scene for scene in _scenes(rows) if any(r["scene"] == scene and r["route"] for r in rows)]
    figure, axes = _grid(len(scenes))
    for ax, scene in zip(axes, scenes):
        of_scene = [row for row in rows if row["scene"] == scene]
        timing = ax.twinx()
        for route, colour in ROUTE_STYLE.items():
            sweep = sorted((row for row in of_scene if row["route"] == route), key=lambda row: row["to_mvc"])
            if sweep:
                share = [100 * r["to_mvc"] for r in sweep]
                ax.plot(share, _floored([r["err_rms"] for r in sweep]), "-o", color=colour, markersize=3,
                        linewidth=1, label=f"error, {route}")
                timing.plot(share, [r["seconds"] * 1e3 for r in sweep], ":", color=colour, linewidth=1,
                            label=f"time, {route}")
        ax.set_yscale("log")
        _plain_log(ax.yaxis)
        ax.set_title(scene, fontsize=9, loc="left")
        ax.set_xlabel("quads sent to mvc (%)", fontsize=8)
        ax.set_ylabel(error_label(of_scene[0]["unit"]) + ", solid", fontsize=8)
        timing.set_ylabel("median ms, dotted", fontsize=8)
        for each in (ax, timing):
            each.tick_params(labelsize=7)
    _legend(figure, axes)
    figure.suptitle("The hybrid's sweep: share of quads to mvc -> RMS error (solid, left) and median time "
                    "(dotted, right)", fontsize=10)
    figure.tight_layout(rect=(0, 0.05, 1, 0.97))
    return _png(figure)


def relative_cost(rows: list[dict]) -> bytes:
    """Each scene's methods and default hybrid: time / split time against error / split error."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.4, 4.4), dpi=100)
    ax = figure.add_subplot()
    for scene in _scenes(rows):
        by_method = {row["method"]: row for row in rows if row["scene"] == scene and not row["route"]}
        split = by_method["split"]
        if not split["err_rms"] > 0:
            continue  # nothing to improve on: the split is exact here
        chosen = [(m, by_method[m]) for m in ("mvc", "bilinear", "projective")]
        hybrid = headline_hybrid(rows, scene)
        if hybrid is not None:
            chosen.append(("hybrid", hybrid))
        for method, row in chosen:
            colour, marker = METHOD_STYLE.get(method, (ROUTE_STYLE["view"], "P"))
            ax.plot(row["seconds"] / split["seconds"], max(row["err_rms"] / split["err_rms"], ERROR_FLOOR), marker,
                    color=colour, label=method, linestyle="none", markersize=6, alpha=0.8)
    ax.axvline(1.0, color="#9ca3af", linewidth=0.8)
    ax.axhline(1.0, color="#9ca3af", linewidth=0.8)
    ax.set_yscale("log")
    _plain_log(ax.yaxis)
    ax.set_xlabel("time / split time", fontsize=9)
    ax.set_ylabel("RMS error / split's RMS error", fontsize=9)
    ax.set_title("Every scene where the split errs: cost and error relative to the split", fontsize=10, loc="left")
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    ax.legend(unique.values(), unique.keys(), fontsize=8, frameon=False)
    figure.tight_layout()
    return _png(figure)


def _legend(figure, axes) -> None:
    """One legend for the whole grid, below it, each label once."""
    unique = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            unique.setdefault(label, handle)
    figure.legend(unique.values(), unique.keys(), loc="lower center", ncol=min(len(unique), 6), fontsize=7,
                  frameon=False)
