"""Run the study over a list of cases and write its CSV, summary and charts into a folder."""

from __future__ import annotations

import datetime
import os
from collections.abc import Callable

from ..atomic import atomic_write
from ..scenes import Scene
from .sweep import StudySettings, prepare, study_scene
from .timing import machine_facts

CSV_NAME = "study.csv"
#: The committed study's table, package data: the demo report reads it (``affinity.report.sections``), the
#: committed summary and charts in ``reports/study`` come from the run that wrote it.
PACKAGE_TABLE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data", "study", CSV_NAME)
SUMMARY_NAME = "summary.md"
CHART_NAMES = ("error_vs_time.png", "hybrid_sweep.png", "relative_cost.png")


def run_cases(cases: list[Scene], settings: StudySettings,
              progress: Callable[[str], None] = lambda line: None) -> tuple[list[dict], list[str]]:
    """Study every case in order. Returns the rows and one line per case that could not be studied."""
    from ..errors import MeshError

    rows, skipped = [], []
    for number, case in enumerate(cases, 1):
        progress(f"[{number}/{len(cases)}] {case.name}")
        try:
            scene = prepare(case, settings)
        except (MeshError, ValueError) as err:
            skipped.append(f"{case.name}: {err}")
            continue
        rows += study_scene(scene, settings)
    return rows, skipped


def write_outputs(rows: list[dict], skipped: list[str], settings: StudySettings, folder: str,
                  command: str, table: str | None = None) -> list[str]:
    """Write the CSV (into ``table``, default ``folder/study.csv``), the markdown summary and the charts
    into ``folder``; return the paths written. The summary links to the table where it is."""
    from . import charts
    from .tables import summary_markdown, write_csv

    os.makedirs(folder, exist_ok=True)
    paths = [table or os.path.join(folder, CSV_NAME),
             *(os.path.join(folder, name) for name in (SUMMARY_NAME, *CHART_NAMES))]
    write_csv(rows, paths[0])
    link = os.path.relpath(os.path.abspath(paths[0]), os.path.abspath(folder)).replace(os.sep, "/")
    when = datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    header = [
        "# Error against run time",
        "",
        f"`{command}`, {when}. Every method and hybrid setting of a scene is drawn by `render.rasterize_quads` "
        f"at {settings.width}x{settings.height} in one process, timed with {settings.warmup} warm-up round and "
        f"{settings.repeat} interleaved repeats (time of the rasterizer call, plus the hybrid's per-frame routing), "
        "and compared with `exact`, the ray / bilinear-patch reference, on the pixels where both show the same quad. "
        "uv errors are "
        f"in texels of a {settings.texture_size}-texel texture (the checker that the PSNR/SSIM images sample); "
        "the crease is the jump of the attribute gradient across each quad's 0-2 diagonal (1-3 for split-13), "
        "in the same unit per pixel, over quads large enough to fit it. "
        f"All rows: [{os.path.basename(paths[0])}]({link}). "
        "Charts: " + ", ".join(f"[{n}]({n})" for n in CHART_NAMES) + ".",
    ]
    if skipped:
        header += ["", "Not studied: " + "; ".join(skipped) + "."]
    with atomic_write(paths[1]) as out:
        out.write(summary_markdown(rows, machine_facts(), header))
    for path, draw in zip(paths[2:], (charts.error_against_time, charts.hybrid_sweep, charts.relative_cost)):
        with atomic_write(path, binary=True) as out:
            out.write(draw(rows))
    return paths
