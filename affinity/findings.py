"""Lint results, kept as arrays per rule so a million findings cost no Python objects."""

from __future__ import annotations

from dataclasses import dataclass, field
from fnmatch import fnmatchcase

import numpy as np


@dataclass(eq=False)
class RuleHits:
    """Every finding of one rule in one file.

    Attributes
    ----------
    code : str
        Rule code, e.g. ``"Q101"``.
    faces : (n,) int64
        0-based face index in file order (counting every face, not only quads).
    lines : (n,) int64
        1-based source line of each face (0 in binary files).
    values : (n,) float64
        The measured score of each face, in the rule's unit.
    threshold : float
        The threshold the values exceeded.
    groups : (n,) int32
        Index into the file's ``group_names`` for each face.
    level : str or None
        ``"error"``, ``"warning"`` or ``"info"`` as the file's settings set it
        (:func:`settle`); None: the rule's default.
    error_above : float or None
        The visibility threshold: a finding whose value is above it is an
        ``error`` whatever ``level`` says (:meth:`levels`); None: no such threshold.
    unit : str or None
        The unit of ``values`` under the file's reading; None: the rule's unit.
    details : list of str or None
        One remark per finding, said after the rule's summary (Q902 names the resource).
    """

    code: str
    faces: np.ndarray
    lines: np.ndarray
    values: np.ndarray
    threshold: float
    groups: np.ndarray
    level: str | None = None
    unit: str | None = None
    details: list[str] | None = None
    error_above: float | None = None

    def __len__(self) -> int:
        return len(self.faces)

    def levels(self) -> np.ndarray:
        """(n,) str: the level of each finding (``error`` above ``error_above``, else ``level``)."""
        from .rules import LEVELS

        return np.asarray(LEVELS)[self.level_ranks()]

    def level_ranks(self) -> np.ndarray:
        """(n,) int8: each finding's level as its index in ``LEVELS`` (0 ``error``, 1 ``warning``, 2 ``info``)."""
        from .rules import LEVELS, RULES

        rank = np.full(len(self), LEVELS.index(self.level or RULES[self.code].level), dtype=np.int8)
        if self.error_above is not None:
            rank[self.values > self.error_above] = 0
        return rank

    def at_or_above(self, level: str) -> RuleHits:
        """The findings at ``level`` or worse (``error`` > ``warning`` > ``info``)."""
        from .rules import LEVELS

        return self.subset(self.level_ranks() <= LEVELS.index(level))

    def subset(self, rows: np.ndarray) -> RuleHits:
        """The findings at ``rows`` (an index array or a boolean mask), level and unit kept."""
        details = None if self.details is None else np.asarray(self.details, dtype=object)[rows].tolist()
        return RuleHits(self.code, self.faces[rows], self.lines[rows], self.values[rows], self.threshold,
                        self.groups[rows], self.level, self.unit, details, self.error_above)


@dataclass(eq=False)
class FileReport:
    """The outcome of checking one file.

    Exactly one of three things holds: ``error`` is set (the file is unreadable,
    Q901), ``skipped`` is set (e.g. ``"lfs-pointer"``), or the file was checked
    and ``hits`` holds its findings (possibly none).

    For a USD stage, ``group_names`` are the mesh prims' paths and
    ``prim_face_start`` (P + 1,) int64 their first faces (see
    :class:`affinity.mesh.Mesh`), so findings can name the prim and count faces
    within it; ``up_axis`` and ``meters_per_unit`` are the stage's. ``notes``
    are the loader's remarks on what it did not check. ``transient`` marks an
    error that says something about this run rather than about the file (an
    internal error, a Dask worker that cannot see the path): such a report is
    never cached.
    """

    path: str
    counts: dict[str, int] = field(default_factory=dict)
    hits: list[RuleHits] = field(default_factory=list)
    group_names: list[str] = field(default_factory=list)
    error: str | None = None
    error_line: int = 0
    skipped: str | None = None
    prim_face_start: np.ndarray | None = None
    up_axis: str | None = None
    meters_per_unit: float | None = None
    notes: list[str] = field(default_factory=list)
    transient: bool = False

    @property
    def n_findings(self) -> int:
        return sum(len(h) for h in self.hits)


def _matches(code: str, prefixes: list[str]) -> bool:
    return any(p == "ALL" or code.startswith(p) for p in prefixes)


def settle(hits: list[RuleHits], settings, group_names: list[str], inline=()) -> list[RuleHits]:
    """Give lint's ``hits`` their level, visibility threshold and unit from ``settings`` and drop the
    suppressed ones.

    Suppressed are the findings in a group that a ``path::group`` per-file
    ignore names (``settings.group_ignores``: glob over ``group_names``) and the
    faces ``inline`` silences: ``(codes, faces (k,) int64)`` pairs from
    ``# affinity: ignore[CODE]`` comments (:mod:`affinity.loaders.suppress`).
    """
    from .rules import RULES

    settled = []
    for h in hits:
        rule = RULES[h.code]
        h.level, h.unit = settings.level(h.code), h.unit or rule.unit_for(settings.measure)
        h.error_above = settings.error_above(h.code)
        silenced = np.zeros(len(h), dtype=bool)
        groups = [i for i, name in enumerate(group_names)
                  if any(fnmatchcase(name, glob) and _matches(h.code, codes) for glob, codes in settings.group_ignores)]
        if groups:
            silenced |= np.isin(h.groups, groups)
        for codes, faces in inline:
            if _matches(h.code, codes):
                silenced |= np.isin(h.faces, faces)
        if silenced.any():
            h = h.subset(~silenced)
        if len(h):
            settled.append(h)
    return settled


def report_to_bytes(report: FileReport) -> bytes:
    """``report`` as a compact blob: a JSON header (fields, then each array's dtype and shape) and the
    arrays' raw bytes, zlib-compressed.

    :func:`report_from_bytes` gives back an equal report (same dtypes, same
    values bit for bit), without pickle, so a damaged blob can only fail to load.
    """
    import json
    import zlib
    from dataclasses import fields

    meta = {f.name: getattr(report, f.name) for f in fields(report) if f.name not in ("hits", "prim_face_start")}
    meta["hits"] = [{"code": h.code, "threshold": h.threshold, "level": h.level, "unit": h.unit,
                     "details": h.details, "error_above": h.error_above} for h in report.hits]
    arrays = [getattr(hits, name) for hits in report.hits for name in _HIT_ARRAYS]
    if report.prim_face_start is not None:
        arrays.append(report.prim_face_start)
    arrays = [np.ascontiguousarray(a) for a in arrays]
    meta["arrays"] = [[a.dtype.str, list(a.shape)] for a in arrays]
    header = json.dumps(meta).encode("utf-8")
    body = b"".join([len(header).to_bytes(4, "little"), header, *(a.tobytes() for a in arrays)])
    return _BLOB_MAGIC + zlib.compress(body, 1)


def report_from_bytes(data: bytes) -> FileReport:
    """The report :func:`report_to_bytes` stored; a damaged blob raises ValueError."""
    import json
    import math
    import zlib

    try:
        if not data.startswith(_BLOB_MAGIC):
            raise ValueError("no report header")
        body = bytearray(zlib.decompress(data[len(_BLOB_MAGIC):]))  # writable, so the arrays are
        size = int.from_bytes(body[:4], "little")
        meta = json.loads(body[4 : 4 + size].decode("utf-8"))
        arrays, offset = [], 4 + size
        for dtype, shape in meta.pop("arrays"):
            count = math.prod(shape)
            arrays.append(np.frombuffer(body, dtype=dtype, count=count, offset=offset).reshape(shape))
            offset += arrays[-1].nbytes
        if offset != len(body):
            raise ValueError("arrays and header disagree")
        hits = [
            RuleHits(h["code"], threshold=h["threshold"], level=h["level"], unit=h["unit"], details=h["details"],
                     error_above=h["error_above"], **dict(zip(_HIT_ARRAYS, arrays[4 * k : 4 * k + 4])))
            for k, h in enumerate(meta.pop("hits"))
        ]
        prim_face_start = arrays[4 * len(hits)] if len(arrays) > 4 * len(hits) else None
        return FileReport(**meta, hits=hits, prim_face_start=prim_face_start)
    except (zlib.error, KeyError, TypeError, IndexError, UnicodeDecodeError) as err:
        raise ValueError(f"not a stored report: {type(err).__name__}: {err}") from None


_HIT_ARRAYS = ("faces", "lines", "values", "groups")
_BLOB_MAGIC = b"QAR2"  # QAR2: hits carry error_above
