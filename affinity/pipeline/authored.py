"""One report per authored mesh in a run (design.md, Clarifications: "USD in a run").

An asset tree as studios ship it has each mesh authored once (``Bishop_geom.usd``) and composed by
several files of a folder run (``Bishop_payload.usd``, ``Bishop.usd``, ``chess_set.usda``). Each
file's report names where its prims' geometry is authored (:attr:`FileReport.prim_sources`); where
several reports compose one authored mesh (same layer, same prim path), its findings are kept in one of
them, the *owner*: the report with the most prims referencing it (the one that sees it through the most
bindings), the first in run order on a tie. The owner's finding carries ``layer`` and ``layer_prim``
(where the mesh is authored) and ``prims``: its own referencing prims, then those of the other checked
files as ``path:/prim``. The other reports drop their findings on it. A run in which no authored mesh is
composed by two files keeps every report as it is.

The owner depends only on the files' prim sources and their order, so the shards of a run, merged
(:mod:`affinity.shards.merge`), choose as the whole run does.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..findings import FileReport


def one_report_per_authored_mesh(reports: list[FileReport]) -> list[FileReport]:
    """``reports`` with each authored mesh's findings in its owner only (see the module docstring); new
    reports where something changed, the others as they were."""
    composed: dict[tuple[str, str], list[tuple[int, list[str]]]] = {}  # source -> [(report, its prims)]
    for r, report in enumerate(reports):
        by_source: dict[tuple[str, str], list[str]] = {}
        for prim, source in _sources(report):
            by_source.setdefault(source, []).append(prim)
        for source, prims in by_source.items():
            composed.setdefault(source, []).append((r, prims))
    owners: dict[int, dict[tuple[str, str], list[str]]] = {}  # owner report -> source -> prims of the others
    dropped: dict[int, set[str]] = {}  # report -> prims whose findings go to another report
    for source, users in composed.items():
        if len(users) < 2:
            continue
        owner = max(users, key=lambda user: (len(user[1]), -user[0]))[0]
        owners.setdefault(owner, {})[source] = [f"{reports[r].path}:{prim}" for r, prims in users if r != owner
                                                for prim in prims]
        for r, prims in users:
            if r != owner:
                dropped.setdefault(r, set()).update(prims)
    if not owners:
        return reports
    return [_owning(_dropping(report, dropped.get(r, set())), owners.get(r, {}))
            for r, report in enumerate(reports)]


def _sources(report: FileReport) -> list[tuple[str, tuple[str, str]]]:
    """(prim, (layer, prim path in it)) for the prims of ``report`` whose geometry's source is known."""
    return [(prim, (source[0], source[1])) for prim, source in report.prim_sources.items()]


def _dropping(report: FileReport, prims: set[str]) -> FileReport:
    """``report`` without its findings on the faces of ``prims`` (their shared entries too)."""
    if not prims or report.prim_face_start is None:
        return report
    groups = np.flatnonzero(np.isin(np.asarray(report.group_names, dtype=object), list(prims)))
    starts = report.prim_face_start
    hits = []
    for h in report.hits:
        on_dropped = np.zeros(len(h), dtype=bool)
        for g in groups.tolist():
            on_dropped |= (h.faces >= starts[g]) & (h.faces < starts[g + 1])
        kept = h if not on_dropped.any() else h.subset(~on_dropped)
        if len(kept):
            hits.append(kept)
    shared = [entry for entry in report.shared if entry["prim"] not in prims]
    return replace(report, hits=hits, shared=shared)


def _owning(report: FileReport, others: dict[tuple[str, str], list[str]]) -> FileReport:
    """``report`` with the other files' prims of each source it owns listed in its shared entries: the entry of
    the source's first prim gets its own referencing prims, then ``others[source]`` (each prim's values padded
    with None: that prim's reading is its own file's)."""
    if not others:
        return report
    entries = {entry["prim"]: entry for entry in report.shared}
    shared = []
    first: dict[tuple[str, str], str] = {}
    own: dict[tuple[str, str], list[str]] = {}
    for prim, source in _sources(report):
        first.setdefault(source, prim)
        own.setdefault(source, []).append(prim)
    for entry in report.shared:
        if entry["prim"] not in {first[source] for source in others if source in first}:
            shared.append(entry)
    for source, other_prims in others.items():
        prim = first[source]
        entry = entries.get(prim, {"prim": prim, "values": {}})
        prims = own[source]
        values = {code: [[face, [*per_prim[:len(prims)], *[None] * len(other_prims)]] for face, per_prim in rows]
                  for code, rows in entry["values"].items()}
        shared.append({"prim": prim, "layer": source[0], "layer_prim": source[1], "prims": [*prims, *other_prims],
                       "values": values})
    return replace(report, shared=shared)
