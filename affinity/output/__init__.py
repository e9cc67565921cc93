"""Output formats for ``affinity check``: one module per format, each with ``write(run, out)``.

``text`` (ruff-style lines), ``json`` (the documented schema), ``sarif`` (SARIF
2.1.0 for code scanning), ``github`` (workflow annotations) and ``junit`` (XML
for CI test reports). This package holds what they share: the flat
:class:`Finding` rows and how a finding is described.
"""

from __future__ import annotations

import dataclasses
import importlib
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..findings import FileReport, RuleHits
from ..rules import LEVELS, RULES, with_unit
from ..settings import Settings
from .names import printable

if TYPE_CHECKING:
    from ..shards.selection import ShardRecord

FORMATS = ("text", "json", "sarif", "github", "junit")
#: SARIF results / GitHub annotations per run without ``--max-findings``: code scanning takes at most 25,000.
RUN_CAP = 5000


@dataclass
class CheckRun:
    """Everything a format writes: the reports (in file order) and how they were produced.

    ``settings`` are the resolved settings for the working directory (files
    governed by another configuration file have their own); ``baselined`` maps a
    path to the number of its findings a baseline hid (None: no baseline was used).
    ``max_findings`` caps the findings the structured formats keep per file and
    rule (the worst; ``--max-findings``); without it SARIF and GitHub output keep
    at most ``run_cap`` per run (:meth:`capped`). ``statistics`` asks for per-rule counts.
    ``shard`` (:class:`affinity.shards.selection.ShardRecord`) is set when the run
    checked one shard of a larger one (``--shard K/N``).
    """

    reports: list[FileReport]
    settings: Settings
    baselined: dict[str, int] | None = None
    max_findings: int | None = None
    statistics: bool = False
    run_cap: int = RUN_CAP
    shard: ShardRecord | None = None

    def tally(self) -> dict[str, int]:
        """Counts for a summary: ``files``, ``checked``, ``unreadable``, ``skipped``, ``findings``, ``baselined``."""
        unreadable = sum(r.error is not None for r in self.reports)
        skipped = sum(r.skipped is not None for r in self.reports)
        return {
            "files": len(self.reports),
            "checked": len(self.reports) - unreadable - skipped,
            "unreadable": unreadable,
            "skipped": skipped,
            "findings": sum(r.n_findings for r in self.reports),
            "baselined": sum((self.baselined or {}).values()),
        }

    def kept(self, report: FileReport) -> list[Finding]:
        """The findings of ``report`` a structured format writes: all, or the worst ``max_findings`` per rule."""
        return file_findings(report, self.max_findings, worst=True)[0]

    def capped(self, findings: list[Finding]) -> list[int]:
        """Indices (rising) of the ``findings`` (of the whole run) a capped format keeps: all with
        ``--max-findings`` or up to ``run_cap`` of them, else the ``run_cap`` worst (:func:`severity`)."""
        if self.max_findings is not None or len(findings) <= self.run_cap:
            return list(range(len(findings)))
        keys = np.array([severity(f) for f in findings], dtype=float)  # (n, 2)
        return np.sort(np.lexsort((keys[:, 1], keys[:, 0]))[: self.run_cap]).tolist()

    def cap_notice(self, kept: int, total: int, what: str) -> str | None:
        """The truncation line (notification and stderr) when the cap left findings out, else None."""
        if kept == total:
            return None
        return (f"{what} truncated: the worst {kept:,} of {total:,} findings are kept (at most {self.run_cap:,} "
                "per run by default; --max-findings N keeps the worst N per file and rule instead)")


@dataclass(slots=True)
class Finding:
    """One finding, as every structured format carries it (design.md, "Rule codes").

    In a USD stage, ``prim`` is the mesh prim's path, ``face`` counts within that
    prim, and ``line``/``column`` are 0; ``prim`` is None in other formats and for
    file-level findings. Where several prims reference one geometry layer
    (:attr:`FileReport.shared`), the finding is reported once: ``prim`` is the first
    of them, ``layer`` and ``layer_prim`` say where the mesh is authored, ``prims``
    lists every referencing prim, ``value`` is the worst over them and
    ``prim_values`` (when their values differ) gives each prim's own (None: no finding there).
    """

    path: str
    line: int
    column: int
    code: str
    name: str
    face: int
    value: float
    threshold: float | None
    unit: str
    level: str
    group: str
    message: str
    prim: str | None = None
    layer: str | None = None
    layer_prim: str | None = None
    prims: list[str] | None = None
    prim_values: list[float | None] | None = None
    shift: float | None = None
    bound: str | None = None
    texture: str | None = None
    role: str | None = None


#: The Finding fields only a USD stage fills: left out of structured output where they are None.
USD_FIELDS = ("prim", "layer", "layer_prim", "prims", "prim_values")
#: The fields of Q101's visible reading (design.md): set where C was read through a texture, else left out.
VISIBLE_FIELDS = ("shift", "bound", "texture", "role")


def finding_dict(f: Finding) -> dict:
    """The finding as a dict with the keys of a JSON finding (the USD-only ones where they apply).

    Shallow: the lists (``prims``) are the finding's own, not copies (``dataclasses.asdict`` deep-copies
    every value, which took 6 s for 8,827 findings naming 32 prims each).
    """
    return {field.name: value for field in dataclasses.fields(f)
            if (value := getattr(f, field.name)) is not None or field.name not in (*USD_FIELDS, *VISIBLE_FIELDS)}


def writer(name: str):
    """The ``write(run, out)`` function of a format, imported only when asked for."""
    return importlib.import_module(f".{name}", __name__).write


def group_name(report: FileReport, index: int) -> str:
    """The name of group ``index`` of a report's mesh ("" when it has none)."""
    return report.group_names[index] if 0 <= index < len(report.group_names) else ""


def _rows(report: FileReport, hits: RuleHits, take: np.ndarray) -> list[tuple[int, Finding]]:
    """``(face in file order, finding)`` for the hits at ``take``."""
    rule = RULES[hits.code]
    # Rules without a threshold (Q204, Q205, Q302) measure something else; no limit to report.
    threshold = None if rule.default_threshold is None else hits.threshold
    faces, groups, lines = hits.faces[take], hits.groups[take], hits.lines[take]
    unit = hits.unit if hits.unit is not None else rule.unit
    details = [None] * len(faces) if hits.details is None else [hits.details[k] for k in np.arange(len(hits))[take]]
    visible = _visible_fields(hits, take, report.path)
    usd = report.prim_face_start is not None
    if usd:  # no lines; faces count within their prim (the file-level face -1 stays -1)
        faces, lines = faces - report.prim_face_start[groups], np.zeros_like(lines)
    shared = {entry["prim"]: entry for entry in report.shared}
    return [
        (order, _shared_geometry(Finding(
            path=report.path,
            line=int(line),
            column=1 if line > 0 else 0,
            code=hits.code,
            name=rule.name,
            face=int(face),
            value=float(value),
            threshold=seen.pop("threshold", threshold),
            unit=seen.pop("unit", unit),
            level=level,
            group=group_name(report, g),
            message=": ".join(filter(None, [rule.summary, seen.pop("remark", None), detail])),
            prim=group_name(report, g) if usd and order >= 0 else None,
            **seen,
        ), shared))
        for order, face, line, value, g, detail, level, seen in zip(
            hits.faces[take].tolist(), faces.tolist(), lines.tolist(),
            hits.values[take].tolist(), groups.tolist(), details, hits.levels()[take].tolist(), visible,
        )
    ]


def _visible_fields(hits: RuleHits, take: np.ndarray, path: str) -> list[dict]:
    """Per finding at ``take``: the Finding fields Q101's visible reading sets (``threshold``, ``unit``,
    ``shift``, ``bound``, ``texture``, ``role``) and the message's ``remark``; empty where C was not read."""
    from ..textures.visible import BOUND_NAMES

    columns = hits.visible
    if columns is None:
        return [{} for _ in range(len(hits.faces[take]))]
    folder = os.path.dirname(os.path.abspath(path))
    rows = []
    for shift, bound, pick in zip(columns.shifts[take].tolist(), columns.bounds[take].tolist(),
                                  columns.picks[take].tolist()):
        if pick < 0 or shift != shift:  # no texture read (NaN shift)
            rows.append({})
            continue
        texture = os.path.relpath(os.path.abspath(columns.textures[pick]), folder)
        rows.append({"threshold": columns.limits[1], "unit": columns.units[pick], "shift": shift,
                     "bound": BOUND_NAMES.get(bound), "texture": texture, "role": columns.roles[pick],
                     "remark": visible_remark(columns.roles[pick], texture, shift)})
    return rows


def visible_remark(role: str, texture: str, shift: float) -> str:
    """What a finding read through a texture says after its rule's summary: which texture and how far the
    split shifts it."""
    return f"the split shifts the {role} texture {texture} by {format_value(shift)} texels"


def _shared_geometry(f: Finding, shared: dict[str, dict]) -> Finding:
    """``f`` with where its geometry is authored and the prims that reference it, when several do."""
    entry = shared.get(f.prim)
    if entry is not None:
        f.layer, f.layer_prim, f.prims = entry["layer"], entry["layer_prim"], entry["prims"]
        f.prim_values = dict((face, values) for face, values in entry["values"].get(f.code, [])).get(f.face)
    return f


def severity(f: Finding) -> tuple[int, float]:
    """A sort key, lowest the worst: (level rank, error first; minus how far the value is beyond the
    threshold, as a ratio; findings without a measured ratio (Q204, Q205, ...) first within their level)."""
    rule = RULES[f.code]
    measured = f.threshold is not None and f.threshold > 0 and rule.flags == "above"
    return LEVELS.index(f.level), -(f.value / f.threshold) if measured else -np.inf


def _worst_first(hits: RuleHits) -> np.ndarray:
    """(n,) int64 order of ``hits`` from the worst value (the rule's ``worst`` end) to the mildest,
    ties in file order."""
    key = hits.values if RULES[hits.code].worst == "lowest" else -hits.values
    return np.lexsort((hits.faces, key))


def file_findings(report: FileReport, limit: int | None = None,
                  worst: bool = False) -> tuple[list[Finding], dict[str, int]]:
    """The findings of one file in source order, and how many each rule left out.

    Parameters
    ----------
    limit : int or None
        Keep at most this many findings per rule; None keeps all.
    worst : bool
        Which ones ``limit`` keeps: the first in file order (text output), or
        the worst values (``--max-findings``).

    Returns
    -------
    findings : list of Finding, sorted by (line, face in file order, code)
    omitted : dict of rule code to the number of findings beyond ``limit``
    """
    rows: list[tuple[int, Finding]] = []
    omitted: dict[str, int] = {}
    for hits in report.hits:
        if limit is not None and len(hits) > limit:
            omitted[hits.code] = len(hits) - limit
            order = np.sort(_worst_first(hits)[:limit]) if worst else np.argsort(hits.faces, kind="stable")[:limit]
        else:
            order = np.argsort(hits.faces, kind="stable")
        rows.extend(_rows(report, hits, order))
    rows.sort(key=lambda row: (row[1].line, row[0], row[1].code))
    return [f for _, f in rows], omitted


def worst_findings(report: FileReport, hits: RuleHits, n: int) -> list[Finding]:
    """The ``n`` worst findings of one rule in one file, worst first."""
    return [f for _, f in _rows(report, hits, _worst_first(hits)[:n])]


def first_findings(report: FileReport, hits: RuleHits, n: int) -> list[Finding]:
    """The first ``n`` findings of one rule in one file, in file order."""
    return [f for _, f in _rows(report, hits, np.argsort(hits.faces, kind="stable")[:n])]


def truncation(run: CheckRun, max_findings: int | None) -> list[dict]:
    """What ``--max-findings`` left out: ``{"path", "code", "kept", "total"}`` per file and rule cut."""
    if max_findings is None:
        return []
    return [{"path": r.path, "code": h.code, "kept": max_findings, "total": len(h)}
            for r in run.reports for h in r.hits if len(h) > max_findings]


def level_counts(reports: list[FileReport]) -> dict[str, int]:
    """Findings per level (``error``, ``warning``, ``info``) over all reports, levels without findings left out."""
    counts = dict.fromkeys(LEVELS, 0)
    for report in reports:
        for hits in report.hits:
            levels, n = np.unique(hits.levels(), return_counts=True)
            for level, count in zip(levels.tolist(), n.tolist()):
                counts[level] += count
    return {level: n for level, n in counts.items() if n}


def statistics(reports: list[FileReport]) -> list[dict]:
    """Per rule with findings: ``{"code", "name", "level", "count"}`` (the worst level of its findings)."""
    levels: dict[str, str] = {}
    for report in reports:
        for hits in report.hits:
            worst = min(hits.levels().tolist(), key=LEVELS.index)
            levels[hits.code] = min(levels.get(hits.code, worst), worst, key=LEVELS.index)
    return [{"code": code, "name": RULES[code].name, "level": levels[code], "count": n}
            for code, n in rule_counts(reports).items()]


def rule_counts(reports: list[FileReport]) -> dict[str, int]:
    """Findings per rule code over all reports, in rule-table order."""
    counts = dict.fromkeys(RULES, 0)
    for report in reports:
        for hits in report.hits:
            counts[hits.code] += len(hits)
    return {code: n for code, n in counts.items() if n}


def format_value(value: float) -> str:
    """A measured value for humans: 4 significant digits, no exponent for everyday sizes."""
    return f"{value:.4g}"


def describe(f: Finding) -> str:
    """The message with the measurement and its unit: ``... (3.2 vs 0.5 texels)``, ``... (0.5 folded fraction)``.

    A finding without a unit (Q902: a missing file measures nothing) is its message alone.
    """
    if not f.unit:
        return f.message
    value = {"at least": ">=", "at most": "<="}.get(f.bound, "") + format_value(f.value)
    measured = value if f.threshold is None else f"{value} vs {format_value(f.threshold)}"
    return f"{f.message} ({with_unit(measured, f.unit)})"


def face_label(f: Finding) -> str:
    """``"face 12"``, ``"/World/Crate face 12"`` in USD; ``""`` for file-level findings (Q205 has face -1)."""
    if f.face < 0:
        return ""
    return f"face {f.face}" if f.prim is None else f"{f.prim} face {f.face}"


def located(f: Finding) -> str:
    """:func:`describe` naming the face, for formats without a text line: ``..., face 12``."""
    return ", ".join(filter(None, [describe(f), face_label(f)]))


def text_line(f: Finding) -> str:
    """The ruff-style line ``path:line:col: CODE name: message (value vs threshold unit) [face F]``
    (design.md); ``path:prim:face N: ...`` in USD, no ``[face]`` for file-level findings."""
    if f.prim is not None:
        return f"{printable(f.path)}:{f.prim}:face {f.face}: {f.code} {f.name}: {describe(f)}{authored_where(f)}"
    face = f" [face {f.face}]" if f.face >= 0 else ""
    return f"{printable(f.path)}:{f.line}:{f.column}: {f.code} {f.name}: {describe(f)}{face}"


def authored_where(f: Finding) -> str:
    """`` [authored in LAYER:/prim, referenced by /a (3.2), /b (1.1)]`` for a finding on geometry several
    prims reference (each prim's own value where they differ); ``""`` otherwise."""
    if f.prims is None:
        return ""
    values = f.prim_values or [None] * len(f.prims)
    prims = ", ".join(p if v is None and f.prim_values is None else f"{p} ({'-' if v is None else format_value(v)})"
                      for p, v in zip(f.prims, values))
    return f" [authored in {printable(working_relative(f.layer) or f.layer)}:{f.layer_prim}, referenced by {prims}]"


def working_relative(path: str) -> str | None:
    """``path`` relative to the working directory with ``/`` separators, None when outside it.

    CI annotations and SARIF locations name files relative to the checkout,
    which is the working directory of a CI step.
    """
    rel = os.path.relpath(os.path.abspath(path), os.getcwd())
    return None if rel.startswith("..") else rel.replace(os.sep, "/")


def value_token(value: float) -> str:
    """A measured value rounded to 6 significant digits: equal for the same quad on every run.

    The per-face measures do not depend on the face's position in the file, so
    this token (with rule, file and group) identifies a finding across face
    reordering and edits elsewhere in the file (baseline, SARIF fingerprints).
    """
    return f"{value:.6g}"

