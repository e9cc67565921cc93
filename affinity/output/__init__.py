"""Output formats for ``affinity check``: one module per format, each with ``write(run, out)``.

``text`` (ruff-style lines), ``json`` (the documented schema), ``sarif`` (SARIF
2.1.0 for code scanning), ``github`` (workflow annotations) and ``junit`` (XML
for CI test reports); :mod:`.cap` keeps a run's SARIF results and GitHub
annotations within the run cap. This package holds what they share: which
findings of a file are written and in which order (:func:`select`, a
:class:`Selection`), the findings as :class:`Columns` (a block of one rule's
findings, so a format writes many rows at a time: time and memory grow with the
findings, with small constants) or as :class:`Finding` rows, and how a finding
is described (:func:`descriptions`, :func:`text_lines`).
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from ..findings import FileReport, RuleHits
from ..rules import LEVELS, RULES, number_spec, number_text, with_unit
from ..settings import Settings
from . import rows
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
    path to the number of its findings a baseline hid (None: no baseline was used);
    ``hidden`` counts per level the findings ``--level`` left out (None: no filter).
    ``max_findings`` caps the findings the structured formats keep per file and
    rule (the worst; ``--max-findings``); without it SARIF and GitHub output keep
    at most ``run_cap`` per run (:func:`affinity.output.cap.cap_findings`). ``fail_on`` is the
    lowest level that fails the run (``--fail-on``). ``statistics`` asks for per-rule counts.
    ``shard`` (:class:`affinity.shards.selection.ShardRecord`) is set when the run
    checked one shard of a larger one (``--shard K/N``).
    """

    reports: list[FileReport]
    settings: Settings
    baselined: dict[str, int] | None = None
    max_findings: int | None = None
    statistics: bool = False
    run_cap: int = RUN_CAP
    fail_on: str = "error"
    hidden: dict[str, int] | None = None
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

    def kept(self, report: FileReport) -> Selection:
        """The findings of ``report`` a structured format writes, in file order: all, or the worst
        ``max_findings`` per rule."""
        return select(report, self.max_findings)


def at_or_above(reports: list[FileReport], level: str) -> tuple[list[FileReport], dict[str, int]]:
    """``reports`` keeping only the findings at ``level`` or worse, and how many were left out per level."""
    hidden = dict.fromkeys(LEVELS[LEVELS.index(level) + 1:], 0)
    kept = []
    for report in reports:
        for hits in report.hits:
            levels, counts = np.unique(hits.level_ranks(), return_counts=True)
            for rank, n in zip(levels.tolist(), counts.tolist()):
                if LEVELS[rank] in hidden:
                    hidden[LEVELS[rank]] += n
        shown = [h for h in (h.at_or_above(level) for h in report.hits) if len(h)]
        kept.append(replace(report, hits=shown))
    return kept, {level: n for level, n in hidden.items() if n}


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
    subdivision_level: int | None = None
    refined_faces_flagged: int | None = None


#: The Finding fields only a USD stage fills: left out of structured output where they are None.
USD_FIELDS = ("prim", "layer", "layer_prim", "prims", "prim_values")
#: The fields of Q101's visible reading (design.md): set where C was read through a texture, else left out.
VISIBLE_FIELDS = ("shift", "bound", "texture", "role")
#: Where a finding was measured on a subdivided surface (design.md, "Subdivision"): left out for the cage.
REFINED_FIELDS = ("subdivision_level", "refined_faces_flagged")
#: The fields of geometry several prims reference (:attr:`Columns.shared`).
SHARED_FIELDS = USD_FIELDS[1:]
#: The Finding fields left out of structured output where they are None.
OPTIONAL_FIELDS = (*USD_FIELDS, *VISIBLE_FIELDS, *REFINED_FIELDS)


def shared_fields(f: Finding) -> dict | None:
    """The :data:`SHARED_FIELDS` of a finding on geometry several prims reference; None for any other."""
    return None if f.prims is None else {name: getattr(f, name) for name in SHARED_FIELDS}


def finding_dict(f: Finding) -> dict:
    """The finding as a dict with the keys of a JSON finding (the USD-only ones where they apply).

    Shallow: the lists (``prims``) are the finding's own, not copies (``dataclasses.asdict`` deep-copies
    every value, which took 6 s for 8,827 findings naming 32 prims each).
    """
    return {name: value for name in Finding.__slots__
            if (value := getattr(f, name)) is not None or name not in OPTIONAL_FIELDS}


def _listed(array: str) -> cached_property:
    """A :class:`Columns` attribute: its array ``array`` as a list, made on first use."""
    return cached_property(lambda columns: getattr(columns, array).tolist())


@dataclass(eq=False)
class Columns:
    """Findings of one rule in one file as columns, for the formats that write many rows at once.

    ``path``, ``code``, ``name``, ``unit`` and ``threshold`` (None for rules
    without one: Q204, Q205, Q302 measure something else) are shared; the rest
    hold one entry a finding: the arrays ``lines`` (n,) int64, ``columns`` (n,)
    int64, ``faces`` (n,) int64 (within its prim in USD), ``values`` (n,) float64
    and ``level_ranks`` (n,) int8 (0 ``error``), for formats that convert a
    column at a time; as lists (:attr:`line`, :attr:`column`, :attr:`face`,
    :attr:`value`, :attr:`level`, made on first use) for those that write a
    finding at a time; and the lists ``group``, ``message`` (the rule's summary,
    with the finding's detail) and ``prim`` (None outside USD and for file-level
    findings). ``shared`` is None unless some of the findings lie on geometry
    several prims reference: then one dict (the :data:`SHARED_FIELDS`) or None a
    finding. ``visible`` is None unless Q101's visible reading read C for some:
    then one dict a finding, empty where C was not read, else the
    :data:`VISIBLE_FIELDS` and the ``threshold`` and ``unit`` of C (the shared
    ones are the texel reading's).
    """

    path: str
    code: str
    name: str
    unit: str
    threshold: float | None
    lines: np.ndarray
    columns: np.ndarray
    faces: np.ndarray
    values: np.ndarray
    level_ranks: np.ndarray
    group: list[str]
    message: list[str]
    prim: list[str | None]
    shared: list[dict | None] | None = None
    visible: list[dict] | None = None

    def __len__(self) -> int:
        return len(self.faces)

    line = _listed("lines")
    column = _listed("columns")
    face = _listed("faces")
    value = _listed("values")

    @cached_property
    def level(self) -> list[str]:
        return np.asarray(LEVELS)[self.level_ranks].tolist()

    @cached_property
    def line_digits(self) -> np.ndarray:
        """``lines`` as text (:func:`.rows.integers`), converted once for the formats that write them twice."""
        return rows.integers(self.lines)

    @cached_property
    def face_digits(self) -> np.ndarray:
        """``faces`` as text (:func:`.rows.integers`), converted once for the formats that write them twice."""
        return rows.integers(self.faces)

    @property
    def plain(self) -> bool:
        """Whether every finding has the shared unit and threshold and no USD sharing (the fast formats' case)."""
        return self.shared is None and self.visible is None

    @property
    def on_faces(self) -> bool:
        """Whether these are plain measured findings on mesh faces, outside USD (the rows whose every text
        is shared or a number: written a column at a time)."""
        return bool(self.plain and self.unit and self.prim[0] is None and self.faces.min(initial=0) >= 0)

    def findings(self) -> list[Finding]:
        shared = self.shared or [None] * len(self)
        visible = self.visible or [{}] * len(self)
        return [Finding(self.path, line, column, self.code, self.name, face, value,
                        read.get("threshold", self.threshold), read.get("unit", self.unit), level, group, message, prim,
                        **(where or {}),
                        **{name: read[name] for name in (*VISIBLE_FIELDS, *REFINED_FIELDS) if name in read})
                for line, column, face, value, level, group, message, prim, where, read in zip(
                    self.line, self.column, self.face, self.value, self.level, self.group, self.message, self.prim,
                    shared, visible)]

    @classmethod
    def of(cls, f: Finding) -> Columns:
        """One finding as columns."""
        where = shared_fields(f)
        read = {name: getattr(f, name) for name in VISIBLE_FIELDS} if f.shift is not None else {}
        read.update({name: getattr(f, name) for name in REFINED_FIELDS if getattr(f, name) is not None})
        read = read or None
        return cls(f.path, f.code, f.name, f.unit, f.threshold, np.array([f.line]), np.array([f.column]),
                   np.array([f.face]), np.array([f.value], dtype=float),
                   np.array([LEVELS.index(f.level)], dtype=np.int8), [f.group], [f.message], [f.prim],
                   None if where is None else [where], None if read is None else [read])


def writer(name: str):
    """The ``write(run, out)`` function of a format, imported only when asked for."""
    return importlib.import_module(f".{name}", __name__).write


def group_name(report: FileReport, index: int) -> str:
    """The name of group ``index`` of a report's mesh ("" when it has none)."""
    return report.group_names[index] if 0 <= index < len(report.group_names) else ""


def columns(report: FileReport, hits: RuleHits, take: np.ndarray, ranks: np.ndarray | None = None) -> Columns:
    """The findings ``take`` (k,) int64 of ``hits`` as :class:`Columns`; ``ranks`` (n,) int8 is
    ``hits.level_ranks()`` where a caller taking many blocks has it already."""
    rule = RULES[hits.code]
    faces, groups, lines = hits.faces[take], hits.groups[take], hits.lines[take]
    usd = report.prim_face_start is not None
    if usd:  # no lines; faces count within their prim (the file-level face -1 stays -1)
        faces, lines = np.where(faces >= 0, faces - report.prim_face_start[groups], faces), np.zeros_like(lines)
    names = np.asarray([*report.group_names, ""], dtype=object)
    group = names[np.where((groups >= 0) & (groups < len(report.group_names)), groups, -1)].tolist()
    visible = None if hits.visible is None else _visible_fields(hits, take, report.path)
    remarks = [None] * len(take) if visible is None else [read.pop("remark", None) for read in visible]
    if hits.refined is not None:
        visible = visible or [{} for _ in range(len(take))]
        for read, level, flagged in zip(visible, hits.refined.levels[take].tolist(),
                                        hits.refined.flagged[take].tolist()):
            read.update(subdivision_level=level, refined_faces_flagged=flagged)
    message = [rule.summary] * len(take)
    details = None if hits.details is None else list(map(hits.details.__getitem__, take.tolist()))
    # Remarks are few (a note on one finding, causes on some): only the rows that have one are joined.
    for row in _remarked(details) | _remarked(remarks):
        message[row] = ": ".join(filter(None, [rule.summary, remarks[row], None if details is None else details[row]]))
    prim = [g if f >= 0 else None for g, f in zip(group, hits.faces[take].tolist())] if usd else [None] * len(take)
    shared = _shared_geometry(report, hits.code, prim, faces.tolist()) if usd and report.shared else None
    return Columns(
        path=report.path, code=hits.code, name=rule.name,
        unit=hits.unit if hits.unit is not None else rule.unit,
        threshold=None if rule.default_threshold is None else hits.threshold,
        lines=lines, columns=(lines > 0).astype(np.int64), faces=faces, values=hits.values[take],
        level_ranks=(hits.level_ranks() if ranks is None else ranks)[take], group=group, message=message, prim=prim,
        shared=shared, visible=visible if visible is not None and any(visible) else None,
    )


def _remarked(remarks: list | None) -> set[int]:
    """The rows of ``remarks`` that are not None."""
    if remarks is None or remarks.count(None) == len(remarks):
        return set()
    return {row for row, remark in enumerate(remarks) if remark is not None}


def _shared_geometry(report: FileReport, code: str, prims: list[str | None],
                     faces: list[int]) -> list[dict | None] | None:
    """Per finding, where its geometry is authored and the prims that reference it (the :data:`SHARED_FIELDS`),
    None where one prim alone has it; None when no finding lies on shared geometry."""
    entries = {entry["prim"]: entry for entry in report.shared}
    values = {prim: dict(entry["values"].get(code, [])) for prim, entry in entries.items()}
    shared = [None if (entry := entries.get(prim)) is None else
              {"layer": entry["layer"], "layer_prim": entry["layer_prim"], "prims": entry["prims"],
               "prim_values": values[prim].get(face)}
              for prim, face in zip(prims, faces)]
    return shared if any(where is not None for where in shared) else None


def _visible_fields(hits: RuleHits, take: np.ndarray, path: str) -> list[dict]:
    """Per finding at ``take``: the Finding fields Q101's visible reading sets (``threshold``, ``unit``,
    ``shift``, ``bound``, ``texture``, ``role``) and the message's ``remark``; empty where C was not read."""
    from ..textures.held import PREFIX as HELD
    from ..textures.visible import BOUND_NAMES

    columns = hits.visible
    folder = os.path.dirname(os.path.abspath(path))
    relative = [texture.removeprefix(HELD) if texture.startswith(HELD) else  # a Blender image: its name
                os.path.relpath(os.path.abspath(texture), folder) for texture in columns.textures]  # once each
    rows = []
    for read, shift, bound, pick in zip(columns.read()[take].tolist(), columns.shifts[take].tolist(),
                                        columns.bounds[take].tolist(), columns.picks[take].tolist()):
        if not read:
            rows.append({})
            continue
        texture = relative[pick]
        rows.append({"threshold": columns.limits[1], "unit": columns.units[pick], "shift": shift,
                     "bound": BOUND_NAMES.get(bound), "texture": texture, "role": columns.roles[pick],
                     "remark": visible_remark(columns.roles[pick], texture, shift)})
    return rows


def visible_remark(role: str, texture: str, shift: float) -> str:
    """What a finding read through a texture says after its rule's summary: which texture and how far the
    split shifts it."""
    return f"the split shifts the {role} texture {texture} by {number_text(shift)} texels"


def badness(hits: RuleHits) -> np.ndarray:
    """(n,) float64 order within a level, lowest the worst: minus how far each value is beyond its own threshold,
    as a ratio (C against visible-warning where Q101 read it, the shift against the threshold elsewhere: one
    unit); -inf for findings without a measured ratio (Q201, Q204, Q205, ...: first within their level)."""
    return -hits.ratios() if hits.ranked_by_ratio else np.full(len(hits), -np.inf)


def worst_first(hits: RuleHits) -> np.ndarray:
    """(n,) int64 order of ``hits`` from the worst (errors first, then the worst values: the rule's ``worst``
    end, as ratios to their own thresholds where the rule flags above one) to the mildest, ties in file order."""
    return np.lexsort((hits.faces, hits.worst_key(), hits.level_ranks()))


@dataclass(eq=False)
class Selection:
    """The findings of one file a format writes, rule by rule, and the order they are written in.

    ``parts`` pairs each rule's hits with the rows taken, (k,) int64; ``order``
    (n,) int64 indexes the concatenation of the parts; ``omitted`` counts per
    rule what a limit left out.
    """

    report: FileReport
    parts: list[tuple[RuleHits, np.ndarray]]
    order: np.ndarray
    omitted: dict[str, int] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.order)

    def _concatenated(self, column) -> np.ndarray:
        return np.concatenate([column(hits)[take] for hits, take in self.parts] or [np.zeros(0)])[self.order]

    def level_ranks(self) -> np.ndarray:
        """(n,) int8 level rank of each finding, in order (0 error)."""
        return self._concatenated(RuleHits.level_ranks).astype(np.int8)

    def badness(self) -> np.ndarray:
        """(n,) float64 :func:`badness` of each finding, in order."""
        return self._concatenated(badness)

    def subset(self, positions: np.ndarray) -> Selection:
        """The findings at ``positions`` (k,) of the order, in that order."""
        return Selection(self.report, self.parts, self.order[positions], self.omitted)

    def _blocks(self, block: int, along: np.ndarray | None):
        """The findings in order, ``block`` at a time (a format's rows of a big file are never all held at
        once): per block its size and, per rule in it, the positions (k,) int64 of its rows in the block, their
        :class:`Columns` and their values of ``along`` (n,) (None without)."""
        starts = np.cumsum([0] + [len(take) for _, take in self.parts])
        ranks = [hits.level_ranks() for hits, _ in self.parts]
        for begin in range(0, len(self.order), block):
            index = self.order[begin : begin + block]
            part = np.searchsorted(starts, index, side="right") - 1
            present = np.flatnonzero(np.bincount(part, minlength=len(self.parts))).tolist()
            rules = []
            for p in present:
                where = np.flatnonzero(part == p)
                hits, take = self.parts[p]
                rules.append((where, columns(self.report, hits, take[index[where] - starts[p]], ranks[p]),
                              None if along is None else along[begin + where]))
            yield len(index), rules

    def formatted(self, format_rows, block: int = 16384, along: np.ndarray | None = None) -> Iterator[list]:
        """``format_rows(columns) -> list`` (one entry a finding, :class:`Columns`) over the findings, yielded
        in order, ``block`` at a time. With ``along`` (n,), values in the selection's order,
        ``format_rows(columns, values)`` gets those of its rows."""
        for n, rules in self._blocks(block, along):
            made = [format_rows(c) if values is None else format_rows(c, values) for _, c, values in rules]
            yield made[0] if len(made) == 1 else _interleaved(n, [where for where, _, _ in rules], made)

    def written(self, format_rows, block: int = 4096, along: np.ndarray | None = None) -> Iterator[str]:
        """The text of ``format_rows(columns)`` over the findings, in order, a block at a time (``along`` as in
        :meth:`formatted`). ``format_rows`` gives its rows whole, separators included: as a grid
        (:func:`.rows.grid`), or as a list of texts (findings whose rows take other shapes)."""
        for n, rules in self._blocks(block, along):
            made = [format_rows(c) if values is None else format_rows(c, values) for _, c, values in rules]
            places = [where for where, _, _ in rules]
            if len(made) == 1:
                yield "".join(made[0]) if isinstance(made[0], list) else rows.text(made[0])
            elif all(isinstance(grid, np.ndarray) for grid in made):
                together = np.zeros((n, max(grid.shape[1] for grid in made)), dtype=np.uint8)
                for where, grid in zip(places, made):
                    together[where, : grid.shape[1]] = grid
                yield rows.text(together)
            else:  # rare: grids beside rows of other shapes (a USD prim's shared geometry), one row at a time
                yield "".join(_interleaved(n, places, [made_rows if isinstance(made_rows, list) else
                                                       [rows.text(row) for row in made_rows] for made_rows in made]))

    def findings(self) -> list[Finding]:
        return [f for block in self.formatted(Columns.findings) for f in block]


def _interleaved(n: int, places: list[np.ndarray], made: list[list]) -> list:
    """The ``n`` rows of a block from each rule's ``made`` rows, which go at its ``places`` (k,) int64."""
    out = np.empty(n, dtype=object)
    for where, made_rows in zip(places, made):
        out[where] = np.fromiter(made_rows, dtype=object, count=len(where))
    return out.tolist()


def select(report: FileReport, limit: int | None = None, order: str = "file") -> Selection:
    """The findings of one file: per rule all, or the worst ``limit`` (errors first); in ``order``:

    ``"file"``: by (line, face, rule code), as the file reads; ``"severity"``:
    errors first, then warnings, then info, each the worst first (:func:`badness`),
    ties in file order.
    """
    parts, omitted = [], {}
    for hits in report.hits:
        take = np.arange(len(hits))
        if limit is not None and len(hits) > limit:
            omitted[hits.code] = len(hits) - limit
            take = np.sort(worst_first(hits)[:limit])
        parts.append((hits, take))
    code_rank = {code: i for i, code in enumerate(RULES)}
    concatenated = Selection(report, parts, np.arange(sum(len(take) for _, take in parts)))
    face = concatenated._concatenated(lambda h: h.faces)
    code = np.concatenate([np.full(len(take), code_rank[h.code]) for h, take in parts] or [np.zeros(0)])
    if order == "file":
        key = (code, face, concatenated._concatenated(lambda h: h.lines))
    else:
        key = (code, face, concatenated.badness(), concatenated.level_ranks())
    return Selection(report, parts, np.lexsort(key), omitted)


def file_findings(report: FileReport, limit: int | None = None) -> tuple[list[Finding], dict[str, int]]:
    """The findings of one file in source order (per rule all, or the worst ``limit``), and how many each
    rule left out."""
    selection = select(report, limit)
    return selection.findings(), selection.omitted


def worst_findings(report: FileReport, hits: RuleHits, n: int) -> list[Finding]:
    """The ``n`` worst findings of one rule in one file, worst first."""
    return columns(report, hits, worst_first(hits)[:n]).findings()


def first_findings(report: FileReport, hits: RuleHits, n: int) -> list[Finding]:
    """The first ``n`` findings of one rule in one file, in file order."""
    return columns(report, hits, np.argsort(hits.faces, kind="stable")[:n]).findings()


def truncation(run: CheckRun, max_findings: int | None) -> list[dict]:
    """What ``--max-findings`` left out: ``{"path", "code", "kept", "total"}`` per file and rule cut."""
    if max_findings is None:
        return []
    return [{"path": r.path, "code": h.code, "kept": max_findings, "total": len(h)}
            for r in run.reports for h in r.hits if len(h) > max_findings]


def level_counts(reports: list[FileReport]) -> dict[str, int]:
    """Findings per level (``error``, ``warning``, ``info``) over all reports, levels without findings left out."""
    counts = np.zeros(len(LEVELS), dtype=np.int64)
    for report in reports:
        for hits in report.hits:
            counts += np.bincount(hits.level_ranks(), minlength=len(LEVELS))
    return {level: int(n) for level, n in zip(LEVELS, counts) if n}


def statistics(reports: list[FileReport]) -> list[dict]:
    """Per rule with findings: ``{"code", "name", "level", "count"}`` (the worst level of its findings)."""
    levels: dict[str, int] = {}
    for report in reports:
        for hits in report.hits:
            levels[hits.code] = min(levels.get(hits.code, len(LEVELS)), int(hits.level_ranks().min()))
    return [{"code": code, "name": RULES[code].name, "level": LEVELS[levels[code]], "count": n}
            for code, n in rule_counts(reports).items()]


def rule_counts(reports: list[FileReport]) -> dict[str, int]:
    """Findings per rule code over all reports, in rule-table order."""
    counts = dict.fromkeys(RULES, 0)
    for report in reports:
        for hits in report.hits:
            counts[hits.code] += len(hits)
    return {code: n for code, n in counts.items() if n}


def measurement_suffixes(c: Columns) -> tuple[str, str]:
    """What follows a value in a description: its unit (``" texels"``, ``"/255"``) where there is no threshold,
    else ``" vs 0.5 texels"``."""
    unit = with_unit("", c.unit)  # what follows the number: " texels", "/255"
    if c.threshold is None:
        return unit, ""
    return "", f" vs {number_text(c.threshold)}{unit}"


def descriptions(c: Columns) -> list[str]:
    """Each message with its measurement and unit: ``... (3.2 vs 0.5 texels)``, ``... (0.5 folded fraction)``.

    A rule without a unit (Q902: a missing file measures nothing) gives the message alone.
    """
    if not c.unit:
        return list(c.message)
    if c.visible is None:
        unit, against = measurement_suffixes(c)
        return [f"{m} ({number_text(v)}{unit}{against})" for m, v in zip(c.message, c.value)]
    return [_described(m, v, read.get("bound"), read.get("threshold", c.threshold), read.get("unit", c.unit))
            for m, v, read in zip(c.message, c.value, c.visible)]


def _described(message: str, value: float, bound: str | None, threshold: float | None, unit: str) -> str:
    """One finding's message with its measurement: ``... (>=12 vs 8/255)`` for a value known only as a bound."""
    value_text = {"at least": ">=", "at most": "<="}.get(bound, "") + number_text(value)
    measured = value_text if threshold is None else f"{value_text} vs {number_text(threshold)}"
    return f"{message} ({with_unit(measured, unit)})"


def describe(f: Finding) -> str:
    """:func:`descriptions` of one finding."""
    return descriptions(Columns.of(f))[0]


def face_label(f: Finding) -> str:
    """``"face 12"``, ``"/World/Crate face 12"`` in USD; ``""`` for file-level findings (Q205 has face -1)."""
    if f.face < 0:
        return ""
    return f"face {f.face}" if f.prim is None else f"{f.prim} face {f.face}"


def text_rows(c: Columns) -> np.ndarray | list[str]:
    """The text lines of ``c``, each ended by a newline: a grid of rows (:func:`.rows.grid`) for findings on
    faces (:attr:`Columns.on_faces`), else a list (:func:`text_lines`)."""
    if c.on_faces:
        return rows.grid([*face_line_pieces(c), b"\n"], len(c))
    return [line + "\n" for line in text_lines(c)]


def text_lines(c: Columns) -> list[str]:
    """The ruff-style lines ``path:line:col: CODE level name: message (value vs threshold unit) [face F]``
    (design.md); ``path:prim:face N: CODE level ...`` in USD; no ``[face]`` for file-level findings. A finding
    at a time: :func:`face_line_pieces` writes the lines of findings on faces a column at a time."""
    path, code, name = printable(c.path), c.code, c.name
    described = descriptions(c)
    where = [""] * len(c) if c.shared is None else [authored_where(s) for s in c.shared]
    return [
        (f"{path}:{prim}:face {face}: " if prim is not None else f"{path}:{line}:{column}: ")
        + f"{code} {level} {name}: {text}" + (f" [face {face}]" if prim is None and face >= 0 else "") + also
        for line, column, face, level, prim, text, also in zip(c.line, c.column, c.face, c.level, c.prim, described,
                                                              where)
    ]


def face_line_pieces(c: Columns, escape=str) -> list[rows.Piece]:
    """The pieces (:mod:`.rows`) of the text lines of findings on faces (:attr:`Columns.on_faces`), without
    line ends, their texts (path, name, unit, messages) passed through ``escape`` (XML for JUnit); each
    number column converted at once, each distinct text encoded once."""
    unit, against = measurement_suffixes(c)
    which, messages = distinct(c.message)
    return [f"{escape(printable(c.path))}:".encode(), c.line_digits, b":", rows.integers(c.columns),
            f": {c.code} ".encode(), rows.choice(c.level_ranks, LEVELS), f" {escape(c.name)}: ".encode(),
            rows.choice(which, [escape(m) for m in messages]), b" (", rows.floats(c.value, number_spec()),
            f"{escape(unit + against)}) [face ".encode(), c.face_digits, b"]"]


def distinct(entries: list) -> tuple[np.ndarray, list]:
    """(n,) intp: the index of each of ``entries`` (texts, or tuples of them) into the distinct entries (in
    order of first appearance), and those entries. One entry throughout (a rule's summary) takes no look-up a
    row."""
    if not entries or entries.count(entries[0]) == len(entries):
        return np.zeros(len(entries), dtype=np.intp), entries[:1]
    unique = list(dict.fromkeys(entries))
    lookup = {entry: i for i, entry in enumerate(unique)}
    return np.fromiter(map(lookup.__getitem__, entries), dtype=np.intp, count=len(entries)), unique


def authored_where(shared: dict | None) -> str:
    """`` [authored in LAYER:/prim, referenced by /a (3.2), /b (1.1)]`` for a finding on geometry several
    prims reference (``shared``: its :data:`SHARED_FIELDS`; each prim's own value where they differ); ``""``
    for one that is not (None)."""
    if shared is None:
        return ""
    values = shared["prim_values"]
    prims = ", ".join(p if values is None else f"{p} ({'-' if v is None else number_text(v)})"
                      for p, v in zip(shared["prims"], values or shared["prims"]))
    layer = printable(working_relative(shared["layer"]) or shared["layer"])
    return f" [authored in {layer}:{shared['layer_prim']}, referenced by {prims}]"


def working_relative(path: str) -> str | None:
    """``path`` relative to the working directory with ``/`` separators, None when outside it.

    CI annotations and SARIF locations name files relative to the checkout,
    which is the working directory of a CI step.
    """
    rel = os.path.relpath(os.path.abspath(path), os.getcwd())
    return None if rel.startswith("..") else rel.replace(os.sep, "/")


#: The format of :func:`value_token`, for formatting many values at once.
VALUE_TOKEN = "%.6g"


def value_token(value: float) -> str:
    """A measured value rounded to 6 significant digits: equal for the same quad on every run.

    The per-face measures do not depend on the face's position in the file, so
    this token (with rule, file and group) identifies a finding across face
    reordering and edits elsewhere in the file (baseline, SARIF fingerprints).
    """
    return VALUE_TOKEN % value

