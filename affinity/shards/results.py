"""A ``--format json`` result read back into the reports, settings and shard record that made it.

The JSON document (:mod:`affinity.output.json`) carries every finding with its
face, line, value, threshold, unit, level, group and message, so the reports it
is read back into write the same document again, and every other format the
same output as the run itself. Four things are rebuilt rather than read:

- a rule's findings of one file become one :class:`~affinity.findings.RuleHits`,
  the rules in rule-table order (as :func:`affinity.lint.lint_mesh` gives them);
- the levels: a rule whose findings are all at one level gets that level; one
  with errors among them gets the other level and, as ``error_above``, the
  largest value below error (the visibility threshold lies between the two);
- a message longer than the rule's summary is the summary and a detail;
- a USD stage's faces count within their prim in JSON: the prims get
  consecutive face ranges in the order they appear (JSON lists a file's findings
  in face order), which keeps the file order of every finding;
- a mesh several prims reference from one geometry layer: its findings' ``layer``,
  ``layer_prim``, ``prims`` and ``prim_values`` become the report's ``shared`` entry.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, fields

import numpy as np

from ..findings import FileReport, RuleHits, VisibleColumns
from ..output.json import SCHEMA, VERSION
from ..rules import RULES
from ..settings import Settings
from .selection import ShardRecord

#: Bytes a shard's result may hold: some 2.5 million findings at about 400 bytes each (json.loads takes
#: about ten times a document's size in memory).
RESULT_BUDGET = 1 << 30
#: Keys of a JSON file entry that are not face counts.
_ENTRY_KEYS = {"path", "findings", "up_axis", "meters_per_unit", "notes", "prim_sources"}


class ResultError(ValueError):
    """A file that is not a readable ``affinity check --format json`` result; the message says why."""


@dataclass
class CheckResult:
    """One JSON result: its reports (in its file order), the settings it was checked with, its
    shard record (None for an unsharded run), whether ``--max-findings`` truncated it, and how
    many findings a baseline hid."""

    path: str
    reports: list[FileReport]
    settings: Settings
    shard: ShardRecord | None
    truncated: bool
    baselined: int


def read_result(path: str) -> CheckResult:
    """Read the JSON result at ``path``; :class:`ResultError` when it cannot be read or is not one."""
    from ..loaders.regular import RefusedFile, read_regular

    try:
        doc = strict_json(read_regular(path, RESULT_BUDGET, "a check result").decode("utf-8"))
    except RefusedFile as err:
        raise ResultError(err.strerror) from None
    except OSError as err:
        raise ResultError(f"cannot read it: {err.strerror or err}") from None
    except RecursionError:
        raise ResultError("not a check result: JSON nested deeper than Python's reader takes") from None
    except (UnicodeDecodeError, ValueError) as err:
        raise ResultError(f"not JSON: {err}") from None
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA or doc.get("version") != VERSION:
        raise ResultError(f"not an affinity check result ({SCHEMA} version {VERSION}, from --format json)")
    try:
        return CheckResult(
            path=path,
            reports=_reports(doc["files"], doc["findings"], settings_from_json(doc["settings"])),
            settings=settings_from_json(doc["settings"]),
            shard=None if "shard" not in doc else shard_record_from_json(doc["shard"]),
            truncated="truncated" in doc,
            baselined=int(doc["summary"]["baselined"]),
        )
    except (KeyError, TypeError, ValueError, AttributeError, IndexError) as err:
        raise ResultError(f"a damaged affinity check result ({type(err).__name__}: {err})") from None


def strict_json(text: str):
    """``text`` parsed as RFC 8259 JSON whose numbers fit the result's columns: ValueError for ``NaN``,
    ``Infinity``, a float beyond float64 (``1e400``) and an integer beyond int64, naming it (a
    RecursionError for nesting deeper than Python's parser takes).

    >>> strict_json('{"value": 1.5, "face": 3}')
    {'value': 1.5, 'face': 3}
    >>> strict_json('[1e400]')
    Traceback (most recent call last):
    ValueError: number out of range: 1e400
    """

    def refuse(number: str):
        raise ValueError(f"number out of range: {number[:40]}")

    def parse_float(number: str) -> float:
        value = float(number)
        return value if math.isfinite(value) else refuse(number)

    def parse_int(number: str) -> int:
        value = int(number) if len(number) <= 20 else refuse(number)
        return value if -(1 << 63) <= value < 1 << 63 else refuse(number)

    def constant(name: str):
        raise ValueError(f"{name} is not a JSON number")

    return json.loads(text, parse_float=parse_float, parse_int=parse_int, parse_constant=constant)


def shard_record_from_json(entry: dict) -> ShardRecord:
    """The :class:`ShardRecord` of a JSON ``shard`` entry, its numbers checked."""
    record = ShardRecord(**entry)
    numbers = (record.index, record.of, record.run_files, *record.positions)
    if not all(type(number) is int for number in numbers) or not 1 <= record.index <= record.of:
        raise ValueError(f"shard numbers that are not a shard K/N with file positions: {entry}")
    if not isinstance(record.run_digest, str) or not isinstance(record.version, str):
        raise ValueError("a shard record without its run's digest or tool version")
    return record


def settings_from_json(entry: dict) -> Settings:
    """The :class:`Settings` whose ``dataclasses.asdict`` is ``entry``."""
    names = {f.name for f in fields(Settings)}
    if not entry.keys() <= names:
        raise ValueError(f"unknown settings {sorted(entry.keys() - names)}")
    return Settings(**entry)


def _reports(files: list[dict], findings: list[dict], settings: Settings) -> list[FileReport]:
    by_path: dict[str, list[dict]] = {entry["path"]: [] for entry in files}
    for finding in findings:
        by_path[finding["path"]].append(finding)
    return [report_from_json(entry, by_path[entry["path"]], settings) for entry in files]


def report_from_json(entry: dict, findings: list[dict], settings: Settings) -> FileReport:
    """The report of one JSON file entry and its findings (in the document's order)."""
    path = entry["path"]
    if "error" in entry:
        return FileReport(path, error=entry["error"], error_line=entry["line"])
    if "skipped" in entry:
        return FileReport(path, skipped=entry["skipped"])
    usd = "up_axis" in entry
    group_names = list(dict.fromkeys(f["group"] for f in findings))
    group_of = {name: g for g, name in enumerate(group_names)}
    groups = np.array([group_of[f["group"]] for f in findings], dtype=np.int32)
    faces = np.array([f["face"] for f in findings], dtype=np.int64)
    prim_face_start = None
    if usd:
        prim_face_start = _prim_face_start(faces, groups, len(group_names))
        faces = faces + prim_face_start[groups]
    codes = np.array([f["code"] for f in findings], dtype=object)
    hits = [_rule_hits(code, [findings[i] for i in rows], faces[rows], groups[rows], settings)
            for code in RULES if len(rows := np.flatnonzero(codes == code))]
    return FileReport(
        path,
        counts={key: value for key, value in entry.items() if key not in _ENTRY_KEYS},
        hits=hits,
        shared=_shared(findings),
        group_names=group_names,
        prim_face_start=prim_face_start,
        up_axis=entry.get("up_axis"),
        meters_per_unit=entry.get("meters_per_unit"),
        notes=list(entry.get("notes", [])),
        prim_sources=entry.get("prim_sources", {}),
    )


def _shared(findings: list[dict]) -> list[dict]:
    """The :attr:`FileReport.shared` entries the findings on shared geometry name (in the order of their prims)."""
    shared: dict[str, dict] = {}
    for f in findings:
        if "prims" not in f:
            continue
        entry = shared.setdefault(f["prim"], {"prim": f["prim"], "layer": f["layer"], "layer_prim": f["layer_prim"],
                                              "prims": f["prims"], "values": {}})
        if "prim_values" in f:
            entry["values"].setdefault(f["code"], []).append([f["face"], f["prim_values"]])
    return list(shared.values())


def _prim_face_start(faces: np.ndarray, groups: np.ndarray, n_groups: int) -> np.ndarray:
    """(P + 1,) int64 consecutive face ranges for the prims, each as long as its highest face + 1.

    ``faces`` (n,) int64 count within their prim (-1 for a file-level finding, in the first prim).
    """
    sizes = np.zeros(n_groups, dtype=np.int64)
    np.maximum.at(sizes, groups, faces + 1)
    return np.concatenate([[0], np.cumsum(sizes)])


def _rule_hits(code: str, rows: list[dict], faces: np.ndarray, groups: np.ndarray, settings: Settings) -> RuleHits:
    """One rule's findings in one file; ``faces`` and ``groups`` (n,) as :class:`RuleHits` keeps them. Findings
    read through a texture (with a ``shift``) become the hits' visible reading, levelled by ``settings``'
    ``visible-*``; the others' level and visibility threshold are rebuilt from them alone."""
    rule = RULES[code]
    values = np.array([f["value"] for f in rows], dtype=np.float64)
    levels = np.array([f["level"] for f in rows], dtype=object)
    visible = np.array(["shift" in f for f in rows], dtype=bool)
    errors = levels == "error"
    level, error_above = "error", None
    if not errors[~visible].all():
        others = set(levels[~visible & ~errors].tolist())
        if len(others) > 1:
            raise ValueError(f"{code} findings at levels {sorted(others)} besides error")
        level = others.pop()
        error_above = float(values[~visible & ~errors].max()) if (errors & ~visible).any() else None
    details = [_detail(rule.summary, f["message"], _visible_remark(f)) for f in rows]
    plain = [f for f in rows if "shift" not in f]
    threshold = plain[0]["threshold"] if plain else settings.threshold(code)
    hits = RuleHits(
        code, faces, np.array([f["line"] for f in rows], dtype=np.int64), values,
        0.0 if threshold is None else float(threshold), groups, level=level,
        unit=plain[0]["unit"] if plain else rule.unit_for(settings.measure),
        details=None if all(d is None for d in details) else details, error_above=error_above,
        visible=_visible_columns(rows, settings) if visible.any() else None,
    )
    if not (hits.levels() == levels).all():
        raise ValueError(f"{code} findings whose levels no visibility threshold explains")
    return hits


def _visible_remark(finding: dict) -> str | None:
    """The remark the text of a finding read through a texture starts with (None for another finding)."""
    from ..output import visible_remark

    if "shift" not in finding:
        return None
    return visible_remark(finding["role"], finding["texture"], finding["shift"])


def _visible_columns(rows: list[dict], settings: Settings) -> VisibleColumns:
    """The visible reading of findings that carry one (``shift``, ``texture``, ``role``, ``unit``, ``bound``);
    a texture is named relative to its mesh's folder, as the JSON names it."""
    import os

    sources = list(dict.fromkeys((f["texture"], f["role"], f["unit"]) for f in rows if "shift" in f))
    picks = np.array([sources.index((f["texture"], f["role"], f["unit"])) if "shift" in f else -1 for f in rows],
                     dtype=np.int32)
    folder = os.path.dirname(os.path.abspath(rows[0]["path"]))
    limits = settings.visible_limits
    return VisibleColumns(
        values=np.array([f["value"] if "shift" in f else np.nan for f in rows], dtype=np.float64),
        shifts=np.array([f.get("shift", np.nan) for f in rows], dtype=np.float64),
        bounds=np.array([{"at least": 1, "at most": 2}.get(f.get("bound"), 0) for f in rows], dtype=np.int8),
        picks=picks, textures=[os.path.normpath(os.path.join(folder, texture)) for texture, _, _ in sources],
        roles=[role for _, role, _ in sources], units=[unit for _, _, unit in sources],
        limits=(limits.error, limits.warning, limits.min_shift), fixed=rows[0]["code"] in settings.levels)


def _detail(summary: str, message: str, remark: str | None = None) -> str | None:
    """What a finding's message says after its rule's summary and ``remark`` (the visible reading's, which
    the reports rebuild from the finding's fields; None: nothing more)."""
    head = summary if remark is None else f"{summary}: {remark}"
    if message == head:
        return None
    if not message.startswith(head + ": "):
        raise ValueError(f"message {message!r} is not the rule's summary")
    return message[len(head) + 2:]
