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
accepts 25,000): every file's findings at the failing level (``--fail-on``)
before anyone's below it, a fair share per file where a level does not fit,
each file's worst first (:func:`affinity.output.cap.cap_findings`), in file
order; a tool execution notification and one line on stderr say per level
what was left out. With ``--max-findings N`` each
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

import numpy as np

from .. import __version__
from ..findings import FileReport
from ..rules import LEVELS, RULES, UNREADABLE, number_spec, rule_page
from . import (
    REFINED_FIELDS,
    VALUE_TOKEN,
    VISIBLE_FIELDS,
    CheckRun,
    Columns,
    Selection,
    authored_where,
    descriptions,
    distinct,
    measurement_suffixes,
    rows,
    statistics,
    truncation,
    working_relative,
)
from .cap import cap_findings
from .json import json_number, json_values

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


def fingerprints(code: str, uri: str, groups: list[str], values: list[float], ordinals: list[int]) -> list[str]:
    """The stable identity of each finding of one rule in one file (see the module docstring); the value
    tokens made in one ``%``."""
    tokens = ((VALUE_TOKEN + "\0") * len(values) % tuple(values)).split("\0")
    return [hashlib.sha256(f"{code}\0{uri}\0{group}\0{token}\0{ordinal}".encode()).hexdigest()[:32]
            for group, token, ordinal in zip(groups, tokens, ordinals)]


def _ordinals(selection: Selection) -> np.ndarray:
    """(n,) int64: each finding's ordinal among the file's findings of the same rule, group and value token,
    in file order (the selection's order)."""
    token = token_ids(np.concatenate([hits.values[take] for hits, take in selection.parts]))[selection.order]
    code = np.concatenate([np.full(len(take), i) for i, (_, take) in enumerate(selection.parts)])[selection.order]
    group = np.concatenate([hits.groups[take] for hits, take in selection.parts])[selection.order]
    position = np.arange(len(selection))
    by_identity = np.lexsort((position, token, group, code))  # file order within each identity
    keys = np.stack([code, group, token])[:, by_identity]
    starts = np.flatnonzero(np.concatenate([[True], (keys[:, 1:] != keys[:, :-1]).any(axis=0)]))
    run_start = np.repeat(starts, np.diff(np.append(starts, len(selection))))
    ordinals = np.empty(len(selection), dtype=np.int64)
    ordinals[by_identity] = position - run_start
    return ordinals


def token_ids(values: np.ndarray) -> np.ndarray:
    """(n,) int64: a number for each of ``values`` (n,) float64, equal where their :func:`value_token` texts
    are equal.

    The token is |x| rounded to 6 significant digits: the digits rint(m), m = |x| 10^(5 - e) in [1e5, 1e6),
    e = floor(log10 |x|), with the exponent e and the sign. Rounding keeps the order, so equal tokens are
    neighbours among the sorted distinct values. Where m is computed within 1e-3 of a rounding tie or of the
    ends of its decade (the relative error of m is about 1e-16), and for zeros, subnormals, infinities and
    NaN, the neighbours' texts are made and compared instead; -0.0 (token ``-0``) is its own.
    """
    distinct, inverse = np.unique(values, return_inverse=True)  # sorted, NaNs as one, last
    with np.errstate(all="ignore"):
        exponent = np.floor(np.log10(np.abs(distinct)))
        mantissa = np.abs(distinct) * 10.0 ** (5 - exponent)
        sure = (np.isfinite(mantissa) & (mantissa > 1e5 + 1e-3) & (mantissa < 1e6 - 0.5 - 1e-3)
                & (np.abs(mantissa - np.floor(mantissa) - 0.5) > 1e-3))
    key = np.stack([np.signbit(distinct), exponent, np.rint(mantissa)])  # (3, k)
    same = (key[:, 1:] == key[:, :-1]).all(axis=0)
    unsure = np.flatnonzero(~(sure[1:] & sure[:-1]))
    if len(unsure):
        tokens = rows.floats([*distinct[unsure].tolist(), *distinct[unsure + 1].tolist()], VALUE_TOKEN)
        same[unsure] = (tokens[: len(unsure)] == tokens[len(unsure) :]).all(axis=1)
    ids = np.concatenate([[0], np.cumsum(~same)])[inverse.ravel()]
    ids[(values == 0) & np.signbit(values)] = len(distinct)
    return ids


PRIM = ',"prim":'


def _result_rows(location: dict, rule_index: dict[str, int]):
    """The SARIF results of a :class:`Columns` as JSON text, each after a comma and with its fingerprint (from
    its ``ordinals``, :func:`_ordinals`): a grid of rows (:mod:`.rows`) for findings on faces, the pieces
    every result of a rule shares encoded once; else a list, a result at a time."""
    encode = json.dumps
    # One encoder for every result (json.dumps with options builds a new encoder a call: most of the time here).
    compact = json.JSONEncoder(separators=(",", ":")).encode

    def result_rows(c: Columns, ordinals: np.ndarray) -> np.ndarray | list[str]:
        head = f',{{"ruleId":{encode(c.code)},"ruleIndex":{rule_index[c.code]},"level":"'
        shared = f',"threshold":{encode(c.threshold)},"unit":{encode(c.unit)},"level":"'
        identities = fingerprints(c.code, location["uri"], c.group, c.value, ordinals.tolist())
        if c.on_faces and ((c.lines > 0).all() or (c.lines == 0).all()):
            return _face_results(c, location, compact, head, shared, identities)
        results = []
        for line, column, face, value, level, group, prim, text, identity, where, read in zip(
                c.line, c.column, c.face, c.value, c.level, c.group, c.prim, descriptions(c), identities,
                c.shared or [None] * len(c), c.visible or [{}] * len(c)):
            located: dict = {"physicalLocation": _physical(location, line, column)}
            logical, label = _logical_location(prim, group, face)
            if logical:
                located["logicalLocations"] = [logical]
            if where is not None or read:  # shared geometry, or C read through a texture: a result of its own
                results.append("," + compact(_rich_result(c, located, where, read, identity, rule_index[c.code], face,
                                                          value, level, group, prim,
                                                          f"{text}, {label}" if label else text)))
                continue
            results.append(
                f'{head}{sarif_level(level)}","message":{{"text":{encode(f"{text}, {label}" if label else text)}}},'
                f'"locations":[{compact(located)}],'
                f'"partialFingerprints":{{"{FINGERPRINT}":"{identity}"}},'
                f'"properties":{{"name":{encode(c.name)},"face":{face},"value":{json_number(value)}{shared}{level}",'
                f'"group":{encode(group)}{"" if prim is None else PRIM + encode(prim)}}}}}')
        return results

    return result_rows


def _face_results(c: Columns, location: dict, compact, head: str, shared: str, identities: list[str]) -> np.ndarray:
    """The results of findings on faces (:attr:`Columns.on_faces`) whose lines are all known or all 0 (binary
    PLY), as a grid of rows (:mod:`.rows`): what :func:`_result_rows` writes a result at a time, laid out a
    column at a time. A JSON text splits where a text does (``dumps(a + b) == dumps(a)[:-1] + dumps(b)[1:]``),
    so each distinct message and group is encoded once, around the numbers."""
    encode = json.dumps
    unit, against = measurement_suffixes(c)
    which_message, messages = distinct(c.message)
    which_group, groups = distinct(c.group)
    region = [b',"region":{"startLine":', c.line_digits, b',"startColumn":', rows.integers(c.columns), b"}"]
    return rows.grid([
        head.encode(), rows.choice(c.level_ranks, [sarif_level(level) for level in LEVELS]),
        b'","message":{"text":', rows.choice(which_message, [encode(m + " (")[:-1] for m in messages]),
        rows.floats(c.value, number_spec()), encode(f"{unit}{against}), face ")[1:-1].encode(), c.face_digits,
        f'"}},"locations":[{{"physicalLocation":{{"artifactLocation":{compact(location)}'.encode(),
        *(region if (c.lines > 0).all() else []),
        b'},"logicalLocations":[{"name":"face ', c.face_digits, b'","fullyQualifiedName":',
        rows.choice(which_group, [encode(f"{g}/face " if g else "face ")[:-1] for g in groups]), c.face_digits,
        f'","kind":"element"}}]}}],"partialFingerprints":{{"{FINGERPRINT}":"'.encode(),
        rows.formatted(identities, "%s"), f'"}},"properties":{{"name":{encode(c.name)},"face":'.encode(),
        c.face_digits, b',"value":', json_values(c), shared.encode(), rows.choice(c.level_ranks, LEVELS),
        b'","group":', rows.choice(which_group, [encode(g) for g in groups]), b"}}"], len(c))


def _rich_result(c: Columns, located: dict, where: dict | None, read: dict, identity: str, rule_index: int,
                 face: int, value: float, level: str, group: str, prim: str | None, text: str) -> dict:
    """A result whose finding lies on geometry several prims reference (``where``: where it is authored, who
    references it) or whose value was read through a texture (``read``: C's threshold and unit, the
    :data:`~affinity.output.VISIBLE_FIELDS`)."""
    properties = {"name": c.name, "face": face, "value": value, "threshold": read.get("threshold", c.threshold),
                  "unit": read.get("unit", c.unit), "level": level, "group": group,
                  **({} if prim is None else {"prim": prim}),
                  **{name: read[name] for name in (*VISIBLE_FIELDS, *REFINED_FIELDS) if read.get(name) is not None}}
    result = {"ruleId": c.code, "ruleIndex": rule_index, "level": sarif_level(level),
              "message": {"text": text + authored_where(where)}, "locations": [located],
              "partialFingerprints": {FINGERPRINT: identity}, "properties": properties}
    if where is not None:
        located["logicalLocations"] = [_prim_location(p) for p in where["prims"]]
        result["relatedLocations"] = [{
            "id": 0, "physicalLocation": {"artifactLocation": artifact_location(where["layer"])},
            "logicalLocations": [_prim_location(where["layer_prim"])],
            "message": {"text": "where the mesh is authored"}}]
        properties.update({k: v for k, v in where.items() if v is not None})
    return result


def _results(run: CheckRun) -> tuple[str, str | None]:
    """The run's results as JSON text (capped, :func:`affinity.output.cap.cap_findings`, unless
    ``--max-findings``), and the truncation notice (None: nothing cut)."""
    selections = [run.kept(report) for report in run.reports]
    kept, notice = [np.arange(len(s)) for s in selections], None
    if run.max_findings is None:
        capped = cap_findings([(s.level_ranks(), s.badness()) for s in selections], run.fail_on, run.run_cap)
        kept, notice = capped.kept, capped.note("SARIF results")
    rule_index = {code: i for i, code in enumerate(RULES)}  # registered rules, as the driver lists them
    results = []
    for selection, taken in zip(selections, kept):
        if len(taken) == 0:
            continue
        location = artifact_location(selection.report.path)
        results += selection.subset(taken).written(_result_rows(location, rule_index),
                                                   along=_ordinals(selection)[taken])
    return "".join(results)[1:], notice  # every result follows a comma but the first


def _prim_location(prim: str) -> dict:
    return {"name": prim.rsplit("/", 1)[-1], "fullyQualifiedName": prim, "kind": "object"}


def _logical_location(prim: str | None, group: str, face: int) -> tuple[dict | None, str]:
    """The USD mesh prim, or the face (qualified by its group), and how the message names the face; (None, "")
    for file-level findings."""
    if face < 0:
        return None, ""
    if prim is not None:
        return _prim_location(prim), f"{prim} face {face}"
    label = f"face {face}"
    return {"name": label, "fullyQualifiedName": "/".join(filter(None, [group, label])), "kind": "element"}, label


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


def document(run: CheckRun) -> tuple[dict, str]:
    """The SARIF log as Python objects, its results standing in as ``[RESULTS]``, and the results as JSON text."""
    properties: dict = {"profile": run.settings.profile, "subdivision": run.settings.subdivision}
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
            "results": [RESULTS],
            **({} if run.shard is None else {"automationDetails": {"id": shard_category(run.shard)}}),
            "properties": properties,
        }],
    }, results


#: Where the results go in the log's text (a string no other value of the log can be).
RESULTS = "\0results\0"


def write(run: CheckRun, out: TextIO) -> None:
    log, results = document(run)
    head, tail = json.dumps(log, separators=(",", ":"), allow_nan=False).split(json.dumps(RESULTS), 1)
    out.write(head + results + tail + "\n")
