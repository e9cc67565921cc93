"""SARIF 2.1.0 output, for GitHub code scanning and other SARIF viewers.

One run whose ``tool.driver.rules`` is the whole rule table (``ruleIndex`` is a
rule's position in it), with descriptions and help from the same source as
``affinity rule``. Each finding is a result located by a physical location —
the file's URI relative to the working directory (``uriBaseId`` ``%SRCROOT%``)
and, when the format has source lines, ``region.startLine`` = the face's line
(binary PLY and USD have none, so there the region is left out) — and by a
logical location: the face, or in a USD stage the mesh prim (kind ``object``,
its path as fully qualified name; the face within it is in the message and the
properties). ``properties`` carry face, value, threshold, group and, in USD, prim. A mesh
that several prims reference from one geometry layer is one result: its logical
locations are every referencing prim, its related location the geometry layer (and the
prim there), and its properties add ``layer``, ``layer_prim``, ``prims`` and, where the
prims' values differ, ``prim_values``.

``partialFingerprints["quadAffinity/v1"]`` identifies a finding across runs: a
hash of rule, file, group and the measured value rounded to 6 significant
digits (:func:`affinity.output.value_token`; it does not change when faces are
reordered or other parts of the file are edited), plus the ordinal among
findings that share all four, in file order. It changes when the quad itself
changes, which makes it a new finding.

Each result's ``level`` is the finding's (SARIF's ``note`` for ``info``).
Without ``--max-findings`` the run keeps at most 5,000 results (code scanning
accepts 25,000), the worst (errors first, then by how far beyond the threshold;
:meth:`affinity.output.CheckRun.capped`), in file order, and says so in a tool
execution notification and one line on stderr. With ``--max-findings N`` each
file keeps the worst N results per rule instead, and the run's
``properties.truncated`` lists, per file and rule cut, how many were kept of
the total; ``--statistics`` adds ``properties.statistics`` (per-rule
counts). The log is written compact.

A shard's log (``--shard K/N``) names its shard in ``automationDetails.id``
(``quad-affinity/shard-K-of-N/``, the category code scanning keys uploads by), so
the shards' uploads do not replace each other; a merged log has none.

Unreadable (Q901) and skipped files are not results: they are tool execution
notifications of the run's invocation, and an unreadable file makes
``executionSuccessful`` false.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path
from typing import TextIO
from urllib.parse import quote

from .. import __version__
from ..findings import FileReport
from ..rules import RULES, UNREADABLE, rule_page
from . import (
    VISIBLE_FIELDS,
    CheckRun,
    Finding,
    authored_where,
    face_label,
    located,
    statistics,
    truncation,
    value_token,
    working_relative,
)

SARIF_VERSION = "2.1.0"
SARIF_SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
SRCROOT = "%SRCROOT%"
FINGERPRINT = "quadAffinity/v1"


def _descriptor(rule) -> dict:
    return {
        "id": rule.code,
        "name": rule.name,
        "shortDescription": {"text": rule.summary},
        "fullDescription": {"text": rule.what},
        "help": {"text": rule_page(rule), "markdown": rule_page(rule, markdown=True)},
        "defaultConfiguration": {"level": sarif_level(rule.level)},
        "properties": {"unit": rule.unit, "defaultThreshold": rule.default_threshold},
    }


def shard_category(shard) -> str:
    """The code scanning category of shard K of N: ``quad-affinity/shard-K-of-N/`` (a trailing ``/``
    makes the whole id the category, with no run id)."""
    return f"quad-affinity/shard-{shard.index}-of-{shard.of}/"


def sarif_level(level: str) -> str:
    """SARIF's word for a level: ``error``, ``warning``, ``note`` (our ``info``)."""
    return "note" if level == "info" else level


def artifact_location(path: str) -> dict:
    """Relative to the working directory under ``%SRCROOT%``; an absolute file URI outside it."""
    rel = working_relative(path)
    if rel is None:
        return {"uri": Path(path).resolve().as_uri()}
    return {"uri": quote(rel), "uriBaseId": SRCROOT}


def _physical(location: dict, line: int, column: int = 0) -> dict:
    physical: dict = {"artifactLocation": location}
    if line > 0:  # SARIF lines start at 1; binary PLY has none
        physical["region"] = {"startLine": line, **({"startColumn": column} if column > 0 else {})}
    return physical


def fingerprint(code: str, uri: str, group: str, value: float, ordinal: int) -> str:
    """The stable identity of a finding (see the module docstring)."""
    text = "\0".join((code, uri, group, value_token(value), str(ordinal)))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:32]


def _numbered(run: CheckRun, report: FileReport) -> list[tuple[Finding, int]]:
    """The file's findings, each with its ordinal among those of the same rule, group and value."""
    seen: dict[tuple, int] = {}
    numbered = []
    for f in run.kept(report):
        identity = (f.code, f.group, value_token(f.value))
        seen[identity] = seen.get(identity, -1) + 1
        numbered.append((f, seen[identity]))
    return numbered


def _result(f: Finding, ordinal: int, location: dict, rule_index: int) -> dict:
    result_location: dict = {"physicalLocation": _physical(location, f.line, f.column)}
    logical = _logical_location(f)
    if logical:
        result_location["logicalLocations"] = [logical]
    result = {
        "ruleId": f.code,
        "ruleIndex": rule_index,
        "level": sarif_level(f.level),
        "message": {"text": located(f) + authored_where(f)},
        "locations": [result_location],
        "partialFingerprints": {FINGERPRINT: fingerprint(f.code, location["uri"], f.group, f.value, ordinal)},
        "properties": {"name": f.name, "face": f.face, "value": f.value,
                       "threshold": f.threshold, "unit": f.unit, "level": f.level, "group": f.group,
                       **({} if f.prim is None else {"prim": f.prim}),
                       **{name: getattr(f, name) for name in VISIBLE_FIELDS if getattr(f, name) is not None}},
    }
    if f.prims is not None:  # geometry several prims reference: where it is authored, and who references it
        result_location["logicalLocations"] = [_prim_location(prim) for prim in f.prims]
        result["relatedLocations"] = [{"id": 0, "physicalLocation": {"artifactLocation": artifact_location(f.layer)},
                                       "logicalLocations": [_prim_location(f.layer_prim)],
                                       "message": {"text": "where the mesh is authored"}}]
        result["properties"].update(layer=f.layer, layer_prim=f.layer_prim, prims=f.prims,
                                    **({} if f.prim_values is None else {"prim_values": f.prim_values}))
    return result


def _results(run: CheckRun) -> tuple[list[dict], str | None]:
    """The run's results (capped, :meth:`CheckRun.capped`) and the truncation notice (None: nothing cut)."""
    rows = [(f, ordinal, report.path) for report in run.reports for f, ordinal in _numbered(run, report)]
    kept = run.capped([f for f, _, _ in rows])
    rule_index = {code: i for i, code in enumerate(RULES)}  # registered rules, as the driver lists them
    locations = {report.path: artifact_location(report.path) for report in run.reports}
    results = [_result(f, ordinal, locations[path], rule_index[f.code])
               for f, ordinal, path in (rows[i] for i in kept)]
    return results, run.cap_notice(len(kept), len(rows), "SARIF results")


def _prim_location(prim: str) -> dict:
    return {"name": prim.rsplit("/", 1)[-1], "fullyQualifiedName": prim, "kind": "object"}


def _logical_location(f: Finding) -> dict | None:
    """The USD mesh prim, or the face (qualified by its group); None for file-level findings."""
    if f.prim is not None:
        return _prim_location(f.prim)
    if not face_label(f):
        return None
    qualified = "/".join(filter(None, [f.group, face_label(f)]))
    return {"name": face_label(f), "fullyQualifiedName": qualified, "kind": "element"}


def _notifications(reports: list[FileReport], truncated: str | None) -> list[dict]:
    notes = [] if truncated is None else [{"level": "warning", "message": {"text": truncated}}]
    for report in reports:
        if report.error is not None:
            notes.append({
                "level": "error",
                "message": {"text": f"{UNREADABLE.code} {UNREADABLE.name}: {report.error}"},
                "descriptor": {"id": UNREADABLE.code, "index": 0},
                "locations": [{"physicalLocation": _physical(artifact_location(report.path), report.error_line)}],
            })
        elif report.skipped is not None:
            notes.append({
                "level": "note",
                "message": {"text": f"skipped ({report.skipped})"},
                "locations": [{"physicalLocation": _physical(artifact_location(report.path), 0)}],
            })
    return notes


def _folder_uri(folder: Path) -> str:
    uri = folder.as_uri()
    return uri if uri.endswith("/") else uri + "/"


def document(run: CheckRun) -> dict:
    """The SARIF log as Python objects."""
    properties: dict = {}
    if run.max_findings is not None:
        properties["truncated"] = truncation(run, run.max_findings)
    if run.statistics:
        properties["statistics"] = statistics(run.reports)
    results, truncated = _results(run)
    if truncated is not None:
        sys.stderr.write(f"affinity: {truncated}\n")
    return {
        "$schema": SARIF_SCHEMA,
        "version": SARIF_VERSION,
        "runs": [{
            "tool": {"driver": {
                "name": "quad-affinity",
                "version": __version__,
                "rules": [_descriptor(rule) for rule in RULES.values()],
                "notifications": [{
                    "id": UNREADABLE.code, "name": UNREADABLE.name,
                    "shortDescription": {"text": UNREADABLE.summary},
                }],
            }},
            "invocations": [{
                "executionSuccessful": all(r.error is None for r in run.reports),
                "toolExecutionNotifications": _notifications(run.reports, truncated),
            }],
            "originalUriBaseIds": {SRCROOT: {"uri": _folder_uri(Path.cwd())}},
            "columnKind": "unicodeCodePoints",
            "results": results,
            **({} if run.shard is None else {"automationDetails": {"id": shard_category(run.shard)}}),
            **({"properties": properties} if properties else {}),
        }],
    }


def write(run: CheckRun, out: TextIO) -> None:
    json.dump(document(run), out, separators=(",", ":"))
    out.write("\n")
