"""The report's sections: one small function each, deciding from the collected data whether it appears.

Every function returns a :class:`Section`. When the scene lacks what the
section needs, the section is ``left_out`` with a one-line reason, and the page
prints that line where the section would be. Adding a section is one function
here, its entry in ``MESH_SECTIONS`` or ``CLOSING_SECTIONS``, and its template
``templates/sections/<key>.html.j2``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..mesh import ATTRIBUTE_NAMES
from ..rules import RULES, resolve_codes, with_unit
from .build import MeshResult, ReportRun
from .images import crop_box, data_uri, heatmap_uri, image_uri, png_bytes, zoomed_uri

#: Methods in the order the renders are shown.
METHOD_ORDER = ("split", "hybrid", "mvc", "exact")
METHOD_CAPTIONS = {
    "split": "two triangles, diagonal 0-2",
    "hybrid": "split, mvc where the split shows",
    "mvc": "mean value coordinates on every quad",
    "exact": "reference: ray / bilinear-patch intersection",
}
WORST_LISTED = 5
ZOOMED_QUADS = 3
ZOOM_SIZE = 168
#: A flagged quad needs this many pixels in the view to be worth a zoomed crop.
MIN_VISIBLE_PIXELS = 9
#: Scores below this fraction of the threshold are affine up to rounding; they go in the first bin.
SCORE_FLOOR = 1e-3
MISSING_ATTRIBUTE = {"texcoords": "no texture coordinates", "colors": "no vertex colours", "normals": "no normals"}
#: Where the stability section looks for ``affinity stability``'s table, in order.
STABILITY_RESULTS = (
    Path("reports/stability/stability.csv"),
    Path(__file__).resolve().parents[2] / "reports" / "stability" / "stability.csv",
)


@dataclass
class Section:
    """One part of the page.

    ``key`` names its template (``templates/sections/<key>.html.j2``); ``data``
    is what the template shows; ``notes`` are one-line remarks on parts left out;
    ``left_out``, when set, replaces the whole section by that one line.
    """

    key: str
    title: str
    data: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    left_out: str | None = None


def leave_out(key: str, title: str, reason: str) -> Section:
    """A section that is not shown, with the one line saying why."""
    return Section(key, title, left_out=reason)


def number(value: float) -> str:
    """Three significant digits; infinity as the sign."""
    return "∞" if value == np.inf else f"{value:.3g}"


def _threshold_text(code: str, threshold: float | None, settings) -> str:
    if threshold is None or RULES[code].default_threshold is None:
        return "—"
    return with_unit(number(threshold), RULES[code].unit_for(settings.measure))


# --- the whole run ----------------------------------------------------------------------------


def file_row(result: MeshResult) -> dict:
    """One file's row: label, status (clean, findings, failed, skipped), message, counts, flags, time."""
    file = result.file
    if file.error is not None:
        status, message = "failed", f"Q901 unreadable: line {file.error_line}: {file.error}"
    elif file.skipped is not None:
        status, message = "skipped", f"skipped ({file.skipped})"
    else:
        status, message = ("findings" if file.hits else "clean"), ""
    return {
        "label": result.input.label,
        "status": status,
        "message": message,
        "counts": file.counts,
        "flags": [(hits.code, len(hits)) for hits in file.hits],
        "seconds": result.seconds,
    }


def _rule_rows(run: ReportRun) -> list[dict]:
    """Every rule enabled here or flagged in some file, with its threshold and totals."""
    enabled = set(resolve_codes(run.settings.select, run.settings.ignore))
    all_hits = [hits for result in run.meshes for hits in result.file.hits]
    rows = []
    for code, rule in RULES.items():
        of_rule = [hits for hits in all_hits if hits.code == code]
        if code in enabled or of_rule:
            rows.append({
                "code": code, "name": rule.name, "summary": rule.summary,
                "threshold": _threshold_text(code, run.settings.threshold(code), run.settings),
                "quads": sum(len(hits) for hits in of_rule), "files": len(of_rule),
            })
    return rows


def summary_section(run: ReportRun) -> Section:
    """Files, faces by size, quads flagged per rule, thresholds, run time."""
    readable = [result for result in run.meshes if result.readable]
    flagged = sum(len(np.unique(np.concatenate([h.faces for h in r.file.hits]))) for r in readable if r.file.hits)
    totals = {key: sum(r.file.counts[key] for r in readable) for key in ("faces", "quads", "triangles", "ngons")}
    facts = [
        ("files", len(run.meshes)),
        ("unreadable", sum(r.file.error is not None for r in run.meshes)),
        ("faces", totals["faces"]),
        ("quads", totals["quads"]),
        ("flagged faces", flagged),
        ("run time", f"{run.seconds:.1f} s"),
    ]
    return Section("summary", "Summary", {
        "facts": facts, "files": [file_row(r) for r in run.meshes], "totals": totals, "rules": _rule_rows(run),
    })


def study_section(run: ReportRun) -> Section:
    """Error against exact over render time of split, hybrid and mvc, per mesh that needed mvc.

    From the renders the report made (one run each, routing included): a first
    look; ``affinity bench`` times with warm-up and repeats and sweeps the
    hybrid's settings.
    """
    from ..draw.drawing import RenderOptions
    from ..study.charts import error_against_time
    from ..study.sweep import mark_pareto

    title = "Error against run time"
    rows = []
    for result in run.meshes:
        errors = _errors_against_exact(result) if result.readable and "exact" in result.renders else None
        if errors is None:
            continue
        unit = RULES[result.shown].unit_for(result.settings.measure)
        of_mesh = [
            {"scene": result.input.label, "method": method, "route": "view" if method == "hybrid" else "",
             "setting": RenderOptions.pixel_tolerance if method == "hybrid" else np.nan,
             "seconds": result.renders[method].seconds, "unit": unit,
             "err_rms": float(np.sqrt(np.mean(error[covered] ** 2))) if covered.any() else 0.0}
            for method, (error, covered) in errors.items()
        ]
        mark_pareto(of_mesh)
        rows += of_mesh
    if not rows:
        return leave_out("study", title,
                         "no mesh has an exact render to compare with (nothing needed mvc in any view)")
    table = [{"mesh": row["scene"], "method": row["method"], "ms": f"{row['seconds'] * 1e3:.1f}",
              "rms": with_unit(number(row["err_rms"]), row["unit"]), "pareto": row["pareto"]} for row in rows]
    chart = error_against_time(rows, time_label="render time (ms), one run")
    return Section("study", title, {"src": data_uri(chart), "rows": table})


def stability_section(run: ReportRun) -> Section:
    """The summary of the stability table (issue 11) from the CSV ``affinity stability`` writes:
    in the current folder's reports/stability/, else the one committed beside the package."""
    from ..stability.table import from_csv, summary

    title = "Numerical stability"
    path = next((p for p in STABILITY_RESULTS if p.is_file()), None)
    if path is None:
        return leave_out("stability", title, "no stability results: `affinity stability` writes them to reports/stability/")
    rows = from_csv(path.read_text(encoding="utf-8"))
    stats = summary(rows)
    return Section("stability", title, {
        "path": "reports/stability/stability.csv", "cases": len({r.case for r in rows}),
        "methods": [s for s in stats if not s["naive"]],
        "naive": [s for s in stats if s["naive"] and s["precision"] == "float64"],
    })


# --- one mesh ---------------------------------------------------------------------------------


def findings_section(result: MeshResult) -> Section:
    """Per rule: how many quads, the threshold, and the worst quads with face index, line and group."""
    title = "Findings"
    if not result.file.hits:
        return leave_out("findings", title, "nothing flagged: every quad passes every enabled rule")
    rows = []
    for hits in result.file.hits:
        severity = hits.values if RULES[hits.code].worst == "lowest" else -hits.values
        unit = RULES[hits.code].unit_for(result.settings.measure)
        worst = [
            {"face": int(hits.faces[i]), "line": int(hits.lines[i]),
             "group": result.file.group_names[hits.groups[i]], "value": with_unit(number(hits.values[i]), unit)}
            for i in np.argsort(severity, kind="stable")[:WORST_LISTED]
        ]
        rows.append({
            "code": hits.code, "name": RULES[hits.code].name, "count": len(hits),
            "threshold": _threshold_text(hits.code, hits.threshold, result.settings), "worst": worst,
        })
    return Section("findings", title, {"rows": rows})


def _shown_text(result: MeshResult) -> str:
    if result.shown == "Q101":
        return f"uv, {result.texture}"
    if result.shown == "Q102":
        return "vertex colours (the mesh has no texture coordinates)"
    return "shading (the mesh has no texture coordinates or vertex colours)"


def _mesh_face_of_pixel(render) -> np.ndarray:
    """(H, W) int64: the mesh face seen at each pixel of a render, -1 where empty."""
    face = render.frame.face
    return np.where(face >= 0, render.faces[np.maximum(face, 0)], -1)


def _zoomed_quads(result: MeshResult) -> tuple[list[dict], str | None]:
    """Crops of every method's render on the worst flagged quads in view, or a note why there are none."""
    scores = result.scores.get(result.shown)
    if scores is None or not scores.flagged.any():
        return [], "no quad is flagged for the attribute shown, so there is nothing to zoom on"
    seen = _mesh_face_of_pixel(result.renders["hybrid"])
    pixels = np.bincount(seen[seen >= 0], minlength=result.mesh.n_faces)
    faces, values = scores.faces[scores.flagged], scores.values[scores.flagged]
    # Worst score first; among equal scores, the quad seen largest.
    order = np.lexsort((-pixels[faces], -values))
    worst = [i for i in order if pixels[faces[i]] >= MIN_VISIBLE_PIXELS][:ZOOMED_QUADS]
    if not worst:
        return [], f"none of the {len(faces)} flagged quads is visible in this view"
    rows = []
    for i in worst:
        face = int(faces[i])
        box = crop_box(seen == face)
        rows.append({
            "face": face, "line": int(result.mesh.face_line[face]),
            "group": result.mesh.group_names[result.mesh.face_group[face]],
            "value": with_unit(number(values[i]), scores.unit), "code": scores.code,
            "crops": [(method, zoomed_uri(result.renders[method].image, box, ZOOM_SIZE))
                      for method in METHOD_ORDER if method in result.renders],
        })
    return rows, None


def renders_section(result: MeshResult) -> Section:
    """split | hybrid | mvc (| exact) side by side, zoomed on the worst flagged quads.

    When nothing needed mvc, only the hybrid (which is then the split) and the line saying so.
    """
    title = "Renders"
    if result.render_error:
        return leave_out("renders", title, f"cannot render: {result.render_error}")
    from ..draw.routing import MVC

    hybrid = result.renders["hybrid"]
    routed = int(np.count_nonzero(hybrid.methods == MVC))
    notes = []
    if routed == 0:
        notes.append(f"nothing needed mvc: the hybrid drew all {len(hybrid.methods)} quads as split (no split error "
                     "reaches the pixel tolerance in this view), so the comparison with mvc is left out")
    notes += [f"{method} left out: {reason}" for method, reason in result.missing.items()]
    figures = [
        {"method": method, "src": image_uri(result.renders[method].image), "what": METHOD_CAPTIONS[method],
         "seconds": result.renders[method].seconds}
        for method in METHOD_ORDER if method in result.renders
    ]
    zoomed = []
    if routed:
        zoomed, why_not = _zoomed_quads(result)
        notes += [why_not] if why_not else []
    return Section("renders", title, {
        "figures": figures, "zoomed": zoomed, "shown": _shown_text(result), "routed": routed,
        "quads": len(hybrid.methods), "from_other_faces": len(hybrid.methods) - result.file.counts["quads"],
    }, notes)


def overlay_section(result: MeshResult) -> Section:
    """The hybrid render with the quads it sent to mvc tinted."""
    title = "Quads sent to mvc"
    if result.overlay is None:
        reason = (f"cannot render: {result.render_error}" if result.render_error
                  else "nothing was sent to mvc in this view, so there is nothing to tint")
        return leave_out("overlay", title, reason)
    from ..draw.drawing import RenderOptions
    from ..draw.routing import MVC

    overlay = result.overlay
    return Section("overlay", title, {
        "src": image_uri(overlay.image), "routed": int(np.count_nonzero(overlay.methods == MVC)),
        "quads": len(overlay.methods), "tolerance": RenderOptions.pixel_tolerance,
    })


def _why_no_exact(result: MeshResult) -> str:
    if result.render_error:
        return f"cannot render: {result.render_error}"
    if "exact" in result.missing:
        return f"render has no exact reference yet ({result.missing['exact']})"
    return "nothing needed mvc in this view, so there is no comparison to map"


def _errors_against_exact(result: MeshResult) -> dict | None:
    """Per-pixel error (H, W) of split, hybrid, mvc and exact against the exact render, in the
    lint's unit of the attribute shown, and the pixels where both show the same quad (H, W) bool
    (the split may show another quad at a concave or bow-tie one); None for plain shading."""
    if result.shown is None:
        return None
    from ..loaders.imagesize import image_size
    from ..measures import pixel_error

    exact = result.renders["exact"].frame
    texture_size = image_size(result.mesh.texture_path()) or (result.settings.texture_size,) * 2
    errors = {}
    for method in ("split", "hybrid", "mvc", "exact"):
        frame = result.renders[method].frame
        covered = (frame.face >= 0) & (frame.face == exact.face)
        error = np.zeros(covered.shape)
        error[covered] = pixel_error(frame.attrs[covered], exact.attrs[covered], RULES[result.shown].attribute,
                                      texture_size)
        errors[method] = error, covered
    return errors


def error_heatmaps_section(result: MeshResult) -> Section:
    """Per-pixel error of split, hybrid and mvc against the exact render, on one colour scale."""
    title = "Error against exact"
    if "exact" not in result.renders:
        return leave_out("errors", title, _why_no_exact(result))
    errors = _errors_against_exact(result)
    if errors is None:
        return leave_out("errors", title, "the renders show plain shading: no attribute to compare")
    del errors["exact"]
    unit = RULES[result.shown].unit_for(result.settings.measure)
    scale = max(float(np.percentile(e[c], 99)) if c.any() else 0.0 for e, c in errors.values())
    figures = [
        {"method": method, "src": heatmap_uri(error, covered, scale),
         "rms": with_unit(number(float(np.sqrt(np.mean(error[covered] ** 2)))) if covered.any() else "—", unit),
         "max": with_unit(number(float(error[covered].max(initial=0.0))), unit)}
        for method, (error, covered) in errors.items()
    ]
    return Section("errors", title, {"figures": figures, "scale": with_unit(number(scale), unit)})


def score_histograms_section(result: MeshResult) -> Section:
    """Histogram of every quad's affinity score per attribute the mesh has, with the threshold marked."""
    from .charts import score_histogram

    title = "Affinity scores"
    charts, skipped = [], []
    for code in (code for code, rule in RULES.items() if rule.scored):
        attribute = ATTRIBUTE_NAMES[RULES[code].attribute]
        scores = result.scores.get(code)
        if scores is None:
            skipped.append(f"{attribute} ({MISSING_ATTRIBUTE[RULES[code].attribute]})")
            continue
        floor = scores.threshold * SCORE_FLOOR
        if not (scores.values >= floor).any():
            below = with_unit(number(floor), scores.unit)
            skipped.append(f"{attribute} (all {len(scores.values)} quads score below {below}: affine up to rounding)")
            continue
        chart = score_histogram(scores.values, scores.threshold, floor, scores.unit,
                                f"{attribute}: {RULES[code].name} ({code})")
        charts.append({
            "attribute": attribute, "src": data_uri(chart), "quads": len(scores.values),
            "flagged": int(np.count_nonzero(scores.flagged)),
            "threshold": with_unit(number(scores.threshold), scores.unit),
            "median": with_unit(number(float(np.median(scores.values))), scores.unit),
            "floored": int(np.count_nonzero(scores.values < floor)), "floor": with_unit(number(floor), scores.unit),
        })
    if not charts:
        return leave_out("scores", title, "no score to plot: " + "; ".join(skipped))
    return Section("scores", title, {"charts": charts}, ["left out: " + "; ".join(skipped)] if skipped else [])


def overview_section(result: MeshResult) -> Section:
    """The 3-D overview from pyvista: the mesh coloured by affinity score, flagged quads outlined."""
    title = "3-D overview"
    if result.overview is None:
        return leave_out("overview", title, result.overview_note)
    scores = result.scores.get(result.shown)
    return Section("overview", title, {
        "src": data_uri(png_bytes(result.overview)),
        "colour": f"{scores.attribute} score ({scores.unit}, log scale)" if scores is not None else "",
    })


#: Sections of each readable mesh, in page order.
MESH_SECTIONS = (
    findings_section, renders_section, overlay_section, error_heatmaps_section, score_histograms_section,
    overview_section,
)
#: Sections after the meshes, about the whole product.
CLOSING_SECTIONS = (study_section, stability_section)
