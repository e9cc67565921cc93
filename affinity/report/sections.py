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

from ..attributes import ATTRIBUTE_NAMES, ATTRIBUTES
from ..findings import FileReport
from ..rules import LEVELS, RULES, UNREADABLE, number_text, resolve_codes, with_unit
from ..study.run import PACKAGE_TABLE
from .build import MeshResult, ReportRun
from .images import data_uri, heat_bar, heatmap_uri, image_uri, png_bytes

#: Methods in the order the renders are shown.
METHOD_ORDER = ("split", "hybrid", "mvc", "exact")
METHOD_CAPTIONS = {
    "split": "two triangles, diagonal 0-2",
    "hybrid": "split, mvc where the split shows",
    "mvc": "mean value coordinates on every quad",
    "exact": "reference: ray / bilinear-patch intersection",
}
WORST_LISTED = 5
#: Scores below this fraction of the threshold are affine up to rounding; they go in the first bin.
SCORE_FLOOR = 1e-3
MISSING_ATTRIBUTE = {field: attribute.missing for field, attribute in ATTRIBUTES.items()}
#: The committed study (``affinity bench --table package``'s table), shipped as package data for the demo report.
STUDY_RESULTS = Path(PACKAGE_TABLE)


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
    return "∞" if value == np.inf else number_text(value, digits=3)


def _threshold_text(code: str, threshold: float | None, settings) -> str:
    if threshold is None or RULES[code].default_threshold is None:
        return "—"
    return with_unit(number(threshold), RULES[code].unit_for(settings.measure))


# --- the whole run ----------------------------------------------------------------------------

#: Stand-ins :func:`affinity.report.page.render_page` fills in last: the time from the command's start to the
#: page rendered (it is in the header and the summary), and the page's own time.
RUN_TIME, PAGE_TIME = "\x00run time\x00", "\x00page time\x00"


def parts_text(parts: dict[str, float]) -> str:
    """``"lint 0.52 s · scores 0.91 s"``: seconds by part, in the order they ran."""
    return " · ".join(f"{part} {seconds:.2f} s" for part, seconds in parts.items())



def verdict(files: list[FileReport], fail_on: str) -> dict:
    """What ``affinity check --fail-on`` with the same settings decides: ``fails`` (a finding at ``fail_on`` or
    above, or an unreadable file), ``fail_on``, ``levels`` (every level -> its findings) and ``unreadable``."""
    from ..output import level_counts

    counts = level_counts(files)
    unreadable = sum(file.error is not None for file in files)
    failing = LEVELS[: LEVELS.index(fail_on) + 1]
    return {"fails": bool(unreadable) or any(counts.get(level) for level in failing), "fail_on": fail_on,
            "levels": {level: counts.get(level, 0) for level in LEVELS}, "unreadable": unreadable}


def file_row(result: MeshResult, fail_on: str) -> dict:
    """One file's row: label, status (passes, fails, unreadable, skipped) at ``fail_on``, message, counts, findings
    per level, flags, time."""
    file = result.file
    judged = verdict([file], fail_on)
    if file.error is not None:
        status, message = "unreadable", f"{UNREADABLE.code} {UNREADABLE.name}: line {file.error_line}: {file.error}"
    elif file.skipped is not None:
        status, message = "skipped", f"skipped ({file.skipped})"
    else:
        status, message = ("fails" if judged["fails"] else "passes"), ""
    return {
        "label": result.input.label,
        "status": status,
        "message": message,
        "counts": file.counts,
        "levels": judged["levels"],
        "flags": [(hits.code, len(hits)) for hits in file.hits],
        "seconds": result.seconds,
        "parts": parts_text(result.parts),
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
    """Files, faces by size, quads flagged per rule, thresholds, the command's run time and its parts."""
    readable = [result for result in run.meshes if result.readable]
    flagged = sum(len(np.unique(np.concatenate([h.faces for h in r.file.hits]))) for r in readable if r.file.hits)
    totals = {key: sum(r.file.counts[key] for r in readable) for key in ("faces", "quads", "triangles", "ngons")}
    facts = [
        ("files", len(run.meshes)),
        ("unreadable", sum(r.file.error is not None for r in run.meshes)),
        ("faces", totals["faces"]),
        ("quads", totals["quads"]),
        ("flagged faces", flagged),
        ("run time", RUN_TIME),
    ]
    return Section("summary", "Summary", {
        "verdict": verdict([r.file for r in run.meshes], run.fail_on),
        "facts": facts, "parts": f"{parts_text(run.parts)} · page {PAGE_TIME}",
        "files": [file_row(r, run.fail_on) for r in run.meshes], "totals": totals, "rules": _rule_rows(run),
    })


def study_section(run: ReportRun) -> Section:
    """Error against run time: the committed study's chart (package data), in the demo report only.

    A report on the user's meshes has one render per method, and one timing is
    noise (the hybrid can come out slower than exact), so it draws no chart;
    ``affinity bench`` times them with warm-up and repeats.
    """
    import csv

    from .charts import study_chart

    title = "Error against run time"
    if not run.demo:
        return leave_out("study", title, "one timed render per method is noise, not a measurement: `affinity bench "
                                         "MESH` times every method with warm-up and repeats")
    rows = list(csv.DictReader(STUDY_RESULTS.read_text(encoding="utf-8").splitlines()))
    scenes = [scene for scene in dict.fromkeys(row["scene"] for row in rows) if not scene.endswith(".obj")]
    repeats = min(int(row["repeats"]) for row in rows if row["repeats"])
    return Section("study", title, {"svg": study_chart(rows, scenes), "repeats": repeats, "scenes": len(scenes)})


# --- one mesh ---------------------------------------------------------------------------------


def _value_text(hits, row: int, unit: str) -> str:
    """Finding ``row`` of ``hits`` as the report writes it: ``2.5 texels``, or ``>=40 1/255`` where Q101 read
    C through a texture (its own unit and bound)."""
    mark, unit = hits.reading(row, unit)
    return mark + with_unit(number(hits.values[row]), unit)


def _place_value_text(result: MeshResult, place, unit: str) -> str:
    """A close-up's worst value as :func:`_value_text` writes it (the rule's unit where no finding has it)."""
    hits = next((h for h in result.file.hits if h.code == place.code), None)
    rows = np.flatnonzero(hits.faces == place.worst) if hits is not None else []
    return _value_text(hits, int(rows[0]), unit) if len(rows) else with_unit(number(place.value), unit)


def findings_section(result: MeshResult) -> Section:
    """Per rule: how many quads, the threshold, and the worst quads with face index, line and group."""
    title = "Findings"
    if not result.file.hits:
        return leave_out("findings", title, "nothing flagged: every quad passes every enabled rule")
    from ..output import worst_first

    rows = []
    for hits in result.file.hits:
        unit = RULES[hits.code].unit_for(result.settings.measure)
        levels = hits.levels()
        worst = [
            {"face": int(hits.faces[i]), "line": int(hits.lines[i]), "level": str(levels[i]),
             "group": result.file.group_names[hits.groups[i]], "value": _value_text(hits, int(i), unit), "usd": False,
             **_in_prim(result.file, hits, int(i))}
            for i in worst_first(hits)[:WORST_LISTED]
        ]
        by_level = dict(zip(*np.unique(levels, return_counts=True)))
        rows.append({
            "code": hits.code, "name": RULES[hits.code].name, "count": len(hits),
            "levels": [(level, int(by_level[level])) for level in LEVELS if level in by_level],
            "threshold": _threshold_text(hits.code, hits.threshold, result.settings), "worst": worst,
        })
    rows.sort(key=lambda row: LEVELS.index(row["levels"][0][0]))  # the rules with errors first
    return Section("findings", title, {"rows": rows})


def _in_prim(file, hits, i: int) -> dict:
    """A USD finding's face as ``affinity check`` numbers it, within its prim (``face``, and ``usd``: no source
    line is shown); nothing for other formats."""
    if file.prim_face_start is None or hits.faces[i] < 0:
        return {}
    return {"face": int(hits.faces[i] - file.prim_face_start[hits.groups[i]]), "usd": True}


def _shown_text(result: MeshResult) -> str:
    """What the renders draw (:attr:`MeshResult.drawn`), and why when it is not the uv."""
    if result.drawn == "uv":
        return f"uv, {result.texture}"
    if result.drawn == "color" and result.mesh.texcoords is None:
        return "vertex colours (the mesh has no texture coordinates)"
    if result.drawn == "color":
        return "vertex colours (the findings are about them, not the uv)"
    return "shading (the mesh has no texture coordinates or vertex colours)"


def renders_section(result: MeshResult) -> Section:
    """split | hybrid | mvc (| exact) side by side, in the overview's view.

    When nothing needed mvc, only the hybrid (which is then the split) and the line saying so.
    """
    title = "Renders"
    if result.render_error:
        return leave_out("renders", title, f"cannot render: {result.render_error}")
    from ..draw import MVC

    hybrid = result.renders["hybrid"]
    routed = int(np.count_nonzero(hybrid.methods == MVC))
    notes = []
    flagged = sum(len(hits) for hits in result.file.hits if hits.code == result.shown)
    if routed == 0 and flagged:
        which = (f"the quad {result.shown} flags" if flagged == 1
                 else f"each of the {flagged:,} quads {result.shown} flags")
        notes.append(f"nothing needed mvc: the hybrid drew all {len(hybrid.methods)} quads as split, because at this "
                     f"distance the split moves the picture by less than {result.options.pixel_tolerance:g} pixel on "
                     f"{which}; the 3-D view and the close-ups show them near, and the comparison with mvc is left out")
    elif routed == 0:
        notes.append(f"nothing needed mvc: the hybrid drew all {len(hybrid.methods)} quads as split (no split error "
                     "reaches the pixel tolerance in this view), so the comparison with mvc is left out")
    figures = [
        {"method": method, "src": image_uri(result.renders[method].image), "what": METHOD_CAPTIONS[method],
         "seconds": result.renders[method].seconds}
        for method in METHOD_ORDER if method in result.renders
    ]
    return Section("renders", title, {
        "figures": figures, "shown": _shown_text(result), "routed": routed,
        "quads": len(hybrid.methods), "from_other_faces": len(hybrid.methods) - result.file.counts["quads"],
    }, notes)


def overlay_section(result: MeshResult) -> Section:
    """The hybrid render with the quads it sent to mvc tinted."""
    title = "Quads sent to mvc"
    if result.render_error:
        return leave_out("overlay", title, f"cannot render: {result.render_error}")
    from ..draw import MVC

    hybrid = result.renders["hybrid"]
    routed = int(np.count_nonzero(hybrid.methods == MVC))
    if routed == 0:
        return leave_out("overlay", title, "nothing was sent to mvc in this view, so there is nothing to tint")
    return Section("overlay", title, {
        "src": image_uri(hybrid.tinted), "routed": routed, "quads": len(hybrid.methods),
        "tolerance": result.options.pixel_tolerance,
    })


def _why_no_exact(result: MeshResult) -> str:
    if result.render_error:
        return f"cannot render: {result.render_error}"
    return "nothing needed mvc in this view, so there is no comparison to map"


def _errors_against_exact(result: MeshResult) -> dict | None:
    """Per-pixel error (H, W) of split, hybrid, mvc and exact against the exact render, in the
    lint's unit of the attribute shown, and the pixels where both show the same quad (H, W) bool
    (the split may show another quad at a concave or bow-tie one); None for plain shading."""
    if result.shown is None:
        return None
    from ..attributes import pixel_error
    from ..lint import quad_texel_grid

    exact = result.renders["exact"].frame
    grid = quad_texel_grid(result.mesh, result.settings)  # each face in its own texture's texels, as the lint
    errors = {}
    for method in ("split", "hybrid", "mvc", "exact"):
        render = result.renders[method]
        frame = render.frame
        covered = (frame.face >= 0) & (frame.face == exact.face)
        error = np.zeros(covered.shape)
        error[covered] = pixel_error(frame.attrs[covered], exact.attrs[covered], RULES[result.shown].attribute,
                                      grid.of(render.faces[frame.face[covered]]))
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
    return Section("errors", title, {"figures": figures, "scale": with_unit(number(scale), unit),
                                     "bar": heat_bar(scale, f"error against exact ({unit})")})


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
            "attribute": attribute, "svg": chart, "quads": len(scores.values),
            "flagged": int(np.count_nonzero(scores.flagged)),
            "threshold": with_unit(number(scores.threshold), scores.unit),
            "median": with_unit(number(float(np.median(scores.values))), scores.unit),
            "floored": int(np.count_nonzero(scores.values < floor)), "floor": with_unit(number(floor), scores.unit),
        })
    if not charts:
        return leave_out("scores", title, "no score to plot: " + "; ".join(skipped))
    return Section("scores", title, {"charts": charts}, ["left out: " + "; ".join(skipped)] if skipped else [])


def face_ranges(faces) -> str:
    """``faces`` (N,) int sorted unique as ranges, ``"0-4,7,9-12"``: the drawn faces of a close-up, for tests."""
    faces = np.asarray(faces)
    if len(faces) == 0:
        return ""
    breaks = np.flatnonzero(np.diff(faces) != 1)
    starts, ends = faces[np.r_[0, breaks + 1]], faces[np.r_[breaks, len(faces) - 1]]
    return ",".join(f"{a}" if a == b else f"{a}-{b}" for a, b in zip(starts.tolist(), ends.tolist()))


#: A close-up's error map ends its ramp at this percentile of the error on the place's own pixels, or on the whole
#: picture where that is larger: the crease across the place spans the ramp (its worst few pixels saturate, the
#: bar says so with its "≥"), where the largest error alone (a spike at one corner) would leave it pale, and a
#: far worse neighbour does not flood the picture.
HEAT_PERCENTILE = 95


def closeup_heat_scale(error: np.ndarray, covered: np.ndarray, own: np.ndarray) -> float:
    """The end of a close-up's heat ramp: the larger ``HEAT_PERCENTILE`` of ``error`` (S, S) float64 over the
    place's pixels ``own`` (S, S) bool and over every pixel, counting those split and exact both cover
    (``covered`` (S, S) bool) only."""
    if not covered.any():
        return 0.0
    place = covered & own
    return float(max(np.percentile(error[covered], HEAT_PERCENTILE),
                     np.percentile(error[place], HEAT_PERCENTILE) if place.any() else 0.0))


def closeups_section(result: MeshResult) -> Section:
    """One close-up per flagged place, worst first: split | hybrid | exact with the place outlined, where the
    crease is faint the split with its difference from exact (or its uv error) amplified (the gain printed),
    and the split's error against exact with its colour bar."""
    title = "Close-ups of the flagged places"
    if not result.places:
        return leave_out("closeups", title, "nothing flagged, so no place to look at")
    if not result.closeups:
        return leave_out("closeups", title, f"--max-views {result.options.max_views}: "
                                            f"{len(result.places)} flagged places not drawn")
    figures = []
    for view in result.closeups:
        place, mesh = view.place, result.mesh
        eye, target, fov = view.view.camera
        rule = RULES[place.code]
        unit = rule.unit_for(result.settings.measure)
        error = None
        if view.error is not None:
            scale = closeup_heat_scale(view.error, view.covered, view.own)
            error = {"src": heatmap_uri(view.error, view.covered, scale),
                     "bar": heat_bar(scale, f"split error against exact ({view.unit})")}
        amplified = (None if view.amplified is None
                     else {"src": image_uri(view.amplified), "label": view.amplified_label})
        difference = (None if view.difference is None else {
            "src": image_uri(view.difference), "label": f"|split − exact| ×{view.difference_gain:g}"})
        figures.append({
            "amplified": amplified, "difference": difference, "amplified_note": view.amplified_note,
            "face": place.worst, "code": place.code, "name": rule.name, "level": place.level,
            "value": _place_value_text(result, place, unit), "faces": len(place.faces),
            "line": int(mesh.face_line[place.worst]), "group": mesh.group_names[mesh.face_group[place.worst]],
            "texture": view.texture, "framed": view.framed, "crease": view.crease, "error": error,
            "images": [(method, image_uri(image)) for method, image in view.images.items()],
            "camera": ",".join(f"{x:.9g}" for x in (*eye, *target, fov)),
            "up": view.view.up, "place": ",".join(map(str, place.faces.tolist())),
            "drawn": face_ranges(view.view.drawn), "place_pixels": view.place_pixels,
        })
    notes = list(result.dropped)
    if len(result.places) > len(figures):
        notes.append(f"{len(result.places) - len(figures)} more flagged places not drawn (--max-views "
                     f"{result.options.max_views}); the UV layout marks every flagged face")
    return Section("closeups", title, {"figures": figures, "places": len(result.places)}, notes)


def _layout_notes(layout) -> list[str]:
    """What the layout picture does not show one quad at a time: uv shared by several faces, quads left out."""
    notes = []
    if layout.distinct < layout.quads:
        shapes = f"{layout.distinct:,} distinct uv shape{'s' * (layout.distinct != 1)}"
        notes.append(f"{layout.faces:,} faces have only {shapes} between them (an n-gon counts its triangles): "
                     "faces with the same uv overlap in texture space (per-face unit squares, mirrored halves) "
                     "and are drawn once, filled toward magenta by the share of them that is flagged")
    if layout.left_out:
        notes.append(f"{layout.left_out:,} distinct uv quads not drawn: the faces pile up in texture space beyond "
                     "the picture's budget (flagged ones are drawn first)")
    return notes


def uv_layout_section(result: MeshResult) -> Section:
    """Every face in texture space, the faces the uv rules flag in the flag colour, their worst places labelled."""
    from .uvlayout import LABELLED, LAYOUT_SIZE, layout_image, layout_svg

    title = "UV layout"
    if result.mesh.texcoords is None:
        return leave_out("uv-layout", title, "the mesh has no texture coordinates")
    # Only the texture-space rules' faces: a colour or normal finding is not fixed in the UV editor.
    uv_rules = {code for code, rule in RULES.items() if rule.attribute == "texcoords"}
    flagged = np.zeros(result.mesh.n_faces, dtype=bool)
    for hits in result.file.hits:
        if hits.code in uv_rules:
            flagged[hits.faces[hits.faces >= 0]] = True
    labelled = list(dict.fromkeys((place.worst, place.code) for place in result.places if place.code in uv_rules))
    layout = layout_image(result.mesh, flagged, LAYOUT_SIZE)
    if layout is None:
        return leave_out("uv-layout", title, "no face has texture coordinates at every corner")
    return Section("uv-layout", title, {"svg": layout_svg(result.mesh, layout, labelled),
                                        "flagged": int(flagged.sum()), "labelled": min(len(labelled), LABELLED)},
                   _layout_notes(layout))


def stability_section(result: MeshResult) -> Section:
    """The drawn pixels of this scene whose mean value coordinates are stiff, checked against mpmath."""
    from .stiffness import STIFF_CONDITION

    title = "Numerical stability"
    found = result.stability
    if found is None:
        return leave_out("stability", title, f"cannot render: {result.render_error}")
    if found.screened == 0:
        return leave_out("stability", title, "no pixel is drawn with mean value coordinates in this view, so none "
                                             "can be stiff (split pixels are triangle barycentrics)")
    if not found.stiff:
        worst = max((pixel.condition for pixel in found.checked), default=0.0)
        return leave_out("stability", title, f"nothing is stiff: of {found.screened} mvc pixels, the "
                         f"{len(found.checked)} where float32 strays most from float64 have condition at most "
                         f"{worst:.3g} (stiff: {STIFF_CONDITION:g}) and errors within tolerance against mpmath")
    rows = [{"face": p.face, "pixel": f"{p.pixel[0]}, {p.pixel[1]}", "condition": f"{p.condition:.3g}",
             "e64": f"{p.error64:.2g}", "t64": f"{p.tolerance64:.2g}", "e32": f"{p.error32:.2g}",
             "t32": f"{p.tolerance32:.2g}", "stiff": p.stiff} for p in found.checked]
    return Section("stability", title, {"rows": rows, "screened": found.screened, "limit": f"{STIFF_CONDITION:g}"})


def overview_section(result: MeshResult) -> Section:
    """The 3-D overview from pyvista: the mesh coloured by affinity score, flagged quads outlined."""
    title = "3-D overview"
    if result.overview is None:
        return leave_out("overview", title, result.overview_note)
    from ..view import score_range

    scores = result.scores.get(result.shown)
    bar = ""
    if scores is not None and len(scores.faces):
        bar = _viridis_bar(*score_range(scores), f"{scores.attribute} score ({scores.unit}, log scale)")
    return Section("overview", title, {
        "src": data_uri(png_bytes(result.overview)), "bar": bar,
        "colour": f"{scores.attribute} score ({scores.unit}, log scale)" if scores is not None else "",
    })


def _viridis_bar(low: float, top: float, label: str) -> str:
    """The overview's log colour scale (matplotlib's viridis, as pyvista draws it) as an inline SVG bar."""
    from matplotlib import colormaps

    from .images import colour_bar

    stops = [tuple(colormaps["viridis"](k / 8)[:3]) for k in range(9)]
    middle = float(np.sqrt(low * top))
    return colour_bar(stops, [(0.0, f"{low:.2g}"), (0.5, f"{middle:.2g}"), (1.0, f"{top:.2g}")], label)


def view3d_section(result: MeshResult) -> Section:
    """The mesh in a 3-D view drawn by the browser (:mod:`affinity.report.scene3d`): split, exact and their
    difference, the findings one click away."""
    title = "3-D view"
    if result.mesh.n_faces == 0 or result.camera is None:
        return leave_out("view3d", title, "the mesh has no faces to show")
    from .scene3d import LEVEL_COLOURS, script_json, shown_text, view_data

    data, notes = view_data(result)
    return Section("view3d", title, {"json": script_json(data), "shown": shown_text(data),
                                     "texture": data["texture"] is not None, "level_colours": LEVEL_COLOURS}, notes)


#: Sections of each readable mesh, in page order.
MESH_SECTIONS = (
    findings_section, view3d_section, closeups_section, uv_layout_section, renders_section, overlay_section,
    error_heatmaps_section, score_histograms_section, stability_section, overview_section,
)
#: Sections after the meshes, about the whole product.
CLOSING_SECTIONS = (study_section,)
