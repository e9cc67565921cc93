"""The study's rows as a CSV file and as the markdown summary.

Rows are dicts with the keys of ``affinity.study.sweep.COLUMNS``.
"""

from __future__ import annotations

import csv
import math

from ..atomic import atomic_write
from ..attributes import ATTRIBUTES, Attribute
from ..lint import scored_codes
from ..rules import RULES, threshold_text, with_unit
from .sweep import COLUMNS


def headline_settings(unit: str) -> dict[str, float]:
    """Route -> the hybrid setting the headline table shows for a scene whose errors are in ``unit``: by
    view the renderer's default pixel tolerance (``RenderOptions.pixel_tolerance``), by lint the default
    threshold of the scored rule of the attribute measured in ``unit`` (the registries': 2/255 for colours)."""
    return {"view": _pixel_tolerance(), "lint error": _lint_rule(unit).default_threshold}


def _pixel_tolerance() -> float:
    """The renderer's default pixel tolerance: the view route's headline setting."""
    from ..draw.drawing import RenderOptions

    return RenderOptions.pixel_tolerance


def attribute_in(unit: str) -> Attribute:
    """The attribute whose errors are measured in ``unit`` (a row's ``unit``; each attribute has its own)."""
    (attribute,) = [attribute for attribute in ATTRIBUTES.values() if attribute.unit == unit]
    return attribute


def error_label(unit: str) -> str:
    """What an axis of RMS errors in ``unit`` is called: ``"RMS uv error (texels)"``."""
    return f"RMS {attribute_in(unit).label} error ({unit})"


def _lint_rule(unit: str):
    """The first scored rule of the attribute whose errors are in ``unit``."""
    return RULES[scored_codes(attribute=attribute_in(unit).name)[0]]


def write_csv(rows: list[dict], path: str) -> None:
    """Every row, every column, floats with 6 significant digits; NaN as an empty cell."""
    with atomic_write(path) as out:
        writer = csv.DictWriter(out, fieldnames=COLUMNS, lineterminator="\n")
        writer.writeheader()
        for row in rows:
            writer.writerow({key: _cell(row[key]) for key in COLUMNS})


def _cell(value) -> str:
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.6g}"
    return str(value)


def headline_hybrid(rows: list[dict], scene: str) -> dict | None:
    """The scene's hybrid row at the headline setting (:func:`headline_settings`, view route first), or None."""
    of_scene = [row for row in rows if row["scene"] == scene]
    for route, setting in headline_settings(of_scene[0]["unit"]).items():
        for row in of_scene:
            if row["route"] == route and math.isclose(row["setting"], setting):
                return row
    return None


def summary_markdown(rows: list[dict], facts: dict[str, str], header: list[str]) -> str:
    """The summary: ``header`` lines, the machine, the headline table, then one table per scene."""
    scenes = list(dict.fromkeys(row["scene"] for row in rows))
    lines = [*header, "", "Machine: " + "; ".join(f"{key} {value}" for key, value in facts.items()) + ".", ""]
    lines += _headline(rows, scenes)
    lines += _headline_in_pixels(rows, scenes)
    for scene in scenes:
        of_scene = [row for row in rows if row["scene"] == scene]
        first = of_scene[0]
        lines += ["", f"### {scene}", "",
                  (f"{first['source']}; {first['quads']:,} quads; {first['width']}x{first['height']}; errors in "
                   f"{first['unit']} against exact on the pixels where both show the same quad; time: median of "
                   f"{first['repeats']} (min-max) after warm-up."), ""]
        lines += _scene_table(of_scene)
    return "\n".join(lines) + "\n"


def _headline(rows: list[dict], scenes: list[str]) -> list[str]:
    by_view = {row["scene"] for row in rows if row["route"] == "view"}
    by_lint = [_lint_rule(unit) for unit in dict.fromkeys(row["unit"] for row in rows if row["scene"] not in by_view)]
    lint = "".join(f"; {ATTRIBUTES[rule.attribute].label} by lint: the {rule.code} threshold, {threshold_text(rule)}"
                   for rule in by_lint)
    lines = [
        "## Where the hybrid sits",
        "",
        (f"Hybrid at the default setting ({_pixel_tolerance():g} px tolerance, by view{lint}). "
         "Times are medians; the time ratios are of the medians and, in brackets, of the fastest runs (less "
         "disturbed by other jobs on a shared machine). Errors are RMS against exact; the last column is the RMS "
         "difference between the splits along the two diagonals."),
        "",
        ("| scene | quads | to mvc | split ms | hybrid ms | mvc ms | hybrid / split | mvc / split | split err "
         "| hybrid err | mvc err | bilinear err | projective err | split 0-2 vs 1-3 |"),
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for scene in scenes:
        by_method = {row["method"]: row for row in rows if row["scene"] == scene and not row["route"]}
        hybrid = headline_hybrid(rows, scene)
        split, mvc = by_method["split"], by_method["mvc"]
        unit = with_unit("", split["unit"])  # what follows a number: " texels", "/255"
        if hybrid is None:
            hybrid_cells = ["—", "—", "—", "—"]
        else:
            hybrid_cells = [f"{hybrid['to_mvc']:.1%}", _ms(hybrid), _ratio(hybrid, split),
                            _num(hybrid["err_rms"]) + unit]
        lines.append(
            f"| {scene} | {split['quads']:,} | {hybrid_cells[0]} | {_ms(split)} | {hybrid_cells[1]} | {_ms(mvc)} "
            f"| {hybrid_cells[2]} | {_ratio(mvc, split)} | {_num(split['err_rms'])}{unit} | {hybrid_cells[3]} "
            f"| {_num(mvc['err_rms'])}{unit} "
            f"| {_num(by_method['bilinear']['err_rms'])}{unit} | {_num(by_method['projective']['err_rms'])}{unit} "
            f"| {_num(by_method['split-13']['diagonal_rms'])}{unit} |"
        )
    return lines


def _headline_in_pixels(rows: list[dict], scenes: list[str]) -> list[str]:
    """The uv errors in screen pixels, the unit of the hybrid's tolerance."""
    lines = [
        "",
        ("The same uv errors in screen pixels (texels over the exact render's local texels per pixel), the unit "
         "of the hybrid's tolerance: 99th percentile / maximum."),
        "",
        "| scene | split px | hybrid px | mvc px | bilinear px | projective px |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for scene in scenes:
        by_method = {row["method"]: row for row in rows if row["scene"] == scene and not row["route"]}
        if math.isnan(by_method["split"]["px_max"]):
            continue  # no texture density: the attribute shown is not a texture's
        hybrid = headline_hybrid(rows, scene)
        cells = [by_method["split"], hybrid, by_method["mvc"], by_method["bilinear"], by_method["projective"]]
        values = ["—" if row is None else f"{_num(row['px_p99'])} / {_num(row['px_max'])}" for row in cells]
        lines.append(f"| {scene} | " + " | ".join(values) + " |")
    return lines


def _scene_table(rows: list[dict]) -> list[str]:
    lines = [
        ("| method | route | setting | to mvc | ms (min-max) | M frag/s | RMS | p99 | max | px p99 | PSNR dB | SSIM "
         "| crease mean / max | Pareto |"),
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|:-:|",
    ]
    for row in rows:
        crease = f"{_num(row['crease_mean'])} / {_num(row['crease_max'])}" if row["crease_quads"] else "—"
        lines.append(
            f"| {row['method']} | {row['route'] or '—'} | {_num(row['setting'])} | {row['to_mvc']:.1%} "
            f"| {_ms(row)} ({row['seconds_min'] * 1e3:.1f}-{row['seconds_max'] * 1e3:.1f}) "
            f"| {row['mfragments_per_s']:.2f} | {_num(row['err_rms'])} | {_num(row['err_p99'])} "
            f"| {_num(row['err_max'])} | {_num(row['px_p99'])} | {_num(row['psnr_db'])} | {_num(row['ssim'], 4)} "
            f"| {crease} | {'✓' if row['pareto'] else ''} |"
        )
    return lines


def _ratio(row: dict, base: dict) -> str:
    """Time of ``row`` over time of ``base``: medians, and fastest runs in brackets."""
    return f"{row['seconds'] / base['seconds']:.2f} ({row['seconds_min'] / base['seconds_min']:.2f})"


def _ms(row: dict) -> str:
    return f"{row['seconds'] * 1e3:.1f}"


def _num(value: float, digits: int = 3) -> str:
    """``digits`` significant digits; "—" for NaN, "∞" for infinity."""
    if isinstance(value, float) and math.isnan(value):
        return "—"
    if value == math.inf:
        return "∞"
    return f"{value:.{digits}g}"
