"""JSON output (schema ``quad-affinity-check``, version 1).

Document layout::

    {
      "schema": "quad-affinity-check", "version": 1,
      "settings": {...resolved settings...},
      "files": [{"path", "faces", "quads", "triangles", "ngons", "findings",
                 USD only: "up_axis", "meters_per_unit", "notes"}
                | {"path", "error", "line"} | {"path", "skipped"}],
      "findings": [{"path", "line", "column", "code", "name", "face", "value",
                    "threshold", "unit", "level", "group", "message", Q101-Q103 only: "measure",
                    USD only: "prim", and where several prims reference one geometry layer
                    "layer", "layer_prim", "prims", "prim_values"; Q101 read through a texture:
                    "shift", "texture", "role", and "bound" ("at least" or "at most") where C is a bound}],
      "summary": {"files", "checked", "unreadable", "skipped", "findings",
                  "baselined", "by_rule": {"Q101": n, ...}, "by_level": {"warning": n, ...},
                  with --level: "not_shown": {"info": n, ...}},
      with --max-findings N: "truncated": [{"path", "code", "kept", "total"}],
      with --statistics: "statistics": [{"code", "name", "level", "count"}],
      with --shard K/N: "shard": {"index", "of", "run_files", "run_digest", "positions", "baseline", "version"}
    }

Written compact (no indentation): machine formats are read by machines. The
findings are written as they are formatted, file by file, so a big run costs
time and memory in proportion to its findings, with small constants.
``level`` is the finding's level (``[levels]`` in the configuration
overrides the rule's); ``unit`` the unit of ``value`` and ``threshold``.
With ``--max-findings N`` each file keeps the worst N findings per rule and
``truncated`` lists, per file and rule cut, how many were kept of the total;
``summary`` still counts every finding.

``face`` is the 0-based index of the face in file order counting every face;
``line`` its 1-based source line (0 in binary PLY); ``value`` the measured score
in the rule's unit, ``threshold`` the limit it exceeded; ``measure`` the reading an
affinity finding's value is in (``error``, ``centre`` or ``barycentric``, from the
resolved ``settings``). In a USD stage,
``prim`` is the mesh prim's path, ``face`` counts within that prim and ``line``
is 0. A mesh that several prims reference from one geometry layer is reported once, at
the first of them: ``layer`` and ``layer_prim`` say where it is authored, ``prims`` lists
the referencing prims, ``value`` is the worst over them and ``prim_values`` (only where
they differ, e.g. different textures bound) each one's, in the order of ``prims``.
``settings`` are the resolved settings for the working directory (a file
governed by another configuration file was checked with that file's settings;
``affinity check --show-settings PATH`` prints them). With ``--baseline``, ``findings`` holds
only the new findings and ``summary.baselined`` counts those the baseline hid.
``shard`` ties a shard's result to its run (:class:`affinity.shards.selection.ShardRecord`);
``affinity merge`` reads these documents back.
"""

from __future__ import annotations

import dataclasses
import json
import math
from typing import TextIO

import numpy as np

from ..findings import FileReport
from ..rules import LEVELS
from . import (
    CheckRun,
    Columns,
    distinct,
    finding_dict,
    level_counts,
    rows,
    rule_counts,
    statistics,
    truncation,
)

SCHEMA = "quad-affinity-check"
VERSION = 1


def _file_entry(report: FileReport) -> dict:
    if report.error is not None:
        return {"path": report.path, "error": report.error, "line": report.error_line}
    if report.skipped is not None:
        return {"path": report.path, "skipped": report.skipped}
    entry = {"path": report.path, **report.counts, "findings": report.n_findings}
    if report.prim_face_start is not None:
        entry.update(up_axis=report.up_axis, meters_per_unit=report.meters_per_unit, notes=report.notes)
        if report.prim_sources:
            entry["prim_sources"] = report.prim_sources
    return entry


def _finding_rows(settings):
    """The JSON text of each finding of a :class:`Columns`, each after a comma: a grid of rows
    (:mod:`.rows`) laid out from per-rule pieces encoded once (the keys of :class:`Finding`, in its order,
    then ``measure``); whole findings encoded one by one where several prims share geometry or a value was
    read through a texture."""

    def finding_rows(c: Columns) -> np.ndarray | list[str]:
        encode = json.dumps
        measure = settings.measure_of(c.code)
        if not c.plain:
            extra = {} if measure is None else {"measure": measure}
            return ["," + encode({**finding_dict(f), **extra}, separators=(",", ":")) for f in c.findings()]
        which, ends = _ends(c, f',"threshold":{encode(c.threshold)},"unit":{encode(c.unit)},"level":"',
                            "}" if measure is None else f',"measure":{encode(measure)}}}')
        return rows.grid([f',{{"path":{encode(c.path)},"line":'.encode(), rows.integers(c.lines), b',"column":',
                          rows.integers(c.columns),
                          f',"code":{encode(c.code)},"name":{encode(c.name)},"face":'.encode(),
                          c.face_digits, b',"value":', json_values(c), rows.choice(which, ends)], len(c))

    return finding_rows


def json_values(c: Columns) -> np.ndarray:
    """(n, w) uint8: the values as JSON text (:func:`.rows.formatted`): a finite float as repr writes it, as
    ``json`` does; NaN and the infinities, which strict JSON (RFC 8259) has no token for, as ``null``."""
    if np.isfinite(c.values).all():
        return rows.floats(c.value, "%r")
    return rows.formatted([json_number(value) for value in c.value], "%s")


def json_number(value: float) -> str:
    """``value`` as strict JSON text: ``null`` for NaN and the infinities.

    >>> json_number(0.1), json_number(float("inf"))
    ('0.1', 'null')
    """
    return json.dumps(value) if math.isfinite(value) else "null"


def _ends(c: Columns, unit: str, tail: str) -> tuple[np.ndarray, list[str]]:
    """Each finding's JSON from its threshold to its end, as (n,) intp indices into the distinct ends: a few
    texts (level, group, message, prim), each encoded once."""
    texts = (c.group, c.message, c.prim)
    if all(column.count(column[0]) == len(column) for column in texts):  # one group, message, prim: by level
        which, keys = c.level_ranks, [(rank, *(column[0] for column in texts)) for rank in range(len(LEVELS))]
    else:
        which, keys = distinct(list(zip(c.level_ranks.tolist(), *texts)))
    return which, [unit + _after_level(LEVELS[rank], *rest) + tail for rank, *rest in keys]


def _after_level(level: str, group: str, message: str, prim: str | None) -> str:
    """A finding's JSON from its level's value to its message (and prim)."""
    return f'{level}","group":{json.dumps(group)},"message":{json.dumps(message)}' + (
        "" if prim is None else f',"prim":{json.dumps(prim)}')


def _summary(run: CheckRun) -> dict:
    summary = {**run.tally(), "by_rule": rule_counts(run.reports), "by_level": level_counts(run.reports)}
    if run.hidden is not None:
        summary["not_shown"] = run.hidden
    return summary


def write(run: CheckRun, out: TextIO) -> None:
    """The document, its findings streamed file by file (in source order within a file)."""
    compact = {"separators": (",", ":"), "allow_nan": False}
    head = {"schema": SCHEMA, "version": VERSION, "settings": dataclasses.asdict(run.settings),
            "files": [_file_entry(r) for r in run.reports]}
    out.write(json.dumps(head, **compact)[:-1] + ',"findings":[')
    finding_rows, first = _finding_rows(run.settings), True
    for report in run.reports:
        for block in run.kept(report).written(finding_rows):
            out.write(block[1:] if first else block)  # every row follows a comma but the first
            first = False
    tail = {"summary": _summary(run)}
    if run.max_findings is not None:
        tail["truncated"] = truncation(run, run.max_findings)
    if run.statistics:
        tail["statistics"] = statistics(run.reports)
    if run.shard is not None:
        tail["shard"] = dataclasses.asdict(run.shard)
    out.write("]," + json.dumps(tail, **compact)[1:] + "\n")
