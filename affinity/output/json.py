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
                  "baselined", "by_rule": {"Q101": n, ...}, "by_level": {"warning": n, ...}},
      with --max-findings N: "truncated": [{"path", "code", "kept", "total"}],
      with --statistics: "statistics": [{"code", "name", "level", "count"}],
      with --shard K/N: "shard": {"index", "of", "run_files", "run_digest", "positions", "baseline", "version"}
    }

Written compact (no indentation): machine formats are read by machines.
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
from typing import TextIO

from ..findings import FileReport
from . import CheckRun, Finding, finding_dict, level_counts, rule_counts, statistics, truncation

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
    return entry


def _finding_entry(f: Finding, settings) -> dict:
    entry = finding_dict(f)
    measure = settings.measure_of(f.code)
    if measure is not None:
        entry["measure"] = measure
    return entry


def document(run: CheckRun) -> dict:
    """The whole JSON document as Python objects."""
    findings = [_finding_entry(f, run.settings) for r in run.reports for f in run.kept(r)]
    doc = {
        "schema": SCHEMA,
        "version": VERSION,
        "settings": dataclasses.asdict(run.settings),
        "files": [_file_entry(r) for r in run.reports],
        "findings": findings,
        "summary": {**run.tally(), "by_rule": rule_counts(run.reports), "by_level": level_counts(run.reports)},
    }
    if run.max_findings is not None:
        doc["truncated"] = truncation(run, run.max_findings)
    if run.statistics:
        doc["statistics"] = statistics(run.reports)
    if run.shard is not None:
        doc["shard"] = dataclasses.asdict(run.shard)
    return doc


def write(run: CheckRun, out: TextIO) -> None:
    # One string, one write: json.dump encodes in Python and writes every token on its own
    # (900,000 writes, 6 s, for 8,827 findings naming 32 prims each); json.dumps uses the C encoder.
    out.write(json.dumps(document(run), separators=(",", ":")) + "\n")
