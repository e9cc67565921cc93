"""Lint results, kept as arrays per rule so a million findings cost no Python objects."""

from __future__ import annotations

from dataclasses import dataclass, field
from fnmatch import fnmatchcase

import numpy as np


@dataclass(eq=False)
class VisibleColumns:
    """Q101's visible reading of a rule's n findings (design.md, "The visible reading").

    Attributes
    ----------
    values : (n,) float64, C (NaN where no texture was read)
    shifts : (n,) float64, the split's shift in texels where C was read, NaN elsewhere
    bounds : (n,) int8, 0 exact, 1 at least (refinement stopped above visible-error), 2 at most
    picks : (n,) int32, index into ``textures``, ``roles`` and ``units`` of the texture behind each C (-1: none)
    textures : the texture files, as the material names them (a UDIM tile: its file)
    roles : their roles, ``base colour``, ``normal``, ``height``, ``scalar`` (a height map whose image is a
        normal map: ``normal (bump)``)
    units : their units, ``1/255`` or ``degrees``
    limits : (visible-error, visible-warning, visible-min-shift)
    fixed : ``[levels]`` gives the rule one level: the limits do not set it
    """

    values: np.ndarray
    shifts: np.ndarray
    bounds: np.ndarray
    picks: np.ndarray
    textures: list[str]
    roles: list[str]
    units: list[str]
    limits: tuple[float, float, float]
    fixed: bool = False

    ARRAYS = ("values", "shifts", "bounds", "picks")

    def subset(self, rows: np.ndarray) -> VisibleColumns:
        return VisibleColumns(*(getattr(self, name)[rows] for name in self.ARRAYS), self.textures, self.roles,
                              self.units, self.limits, self.fixed)

    def levels(self) -> np.ndarray:
        """(n,) str: the visible reading's level where C was read, "" elsewhere."""
        from .textures.visible import VisibleLimits

        levels = np.full(len(self.shifts), "", dtype=object)
        if self.fixed:
            return levels
        read = np.isfinite(self.shifts)
        levels[read] = VisibleLimits(*self.limits).levels(self.values[read], self.shifts[read])
        return levels


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
    visible : VisibleColumns or None
        Q101's visible reading: where it read C, ``values`` hold C and the level follows the
        ``visible-*`` settings (None: no texture was read).
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
    visible: VisibleColumns | None = None

    def __len__(self) -> int:
        return len(self.faces)

    def levels(self) -> np.ndarray:
        """(n,) str: the level of each finding (``error`` above ``error_above``, else ``level``)."""
        from .rules import RULES

        level = self.level or RULES[self.code].level
        if self.error_above is None:
            levels = np.full(len(self), level)
        else:
            levels = np.where(self.values > self.error_above, "error", level)
        if self.visible is not None:
            visible = self.visible.levels()
            levels = np.where(visible != "", visible, levels.astype(object)).astype(str)
        return levels

    def reading(self, row: int, unit: str) -> tuple[str, str]:
        """How finding ``row``'s value reads: its bound mark (``">="``, ``"<="`` or ``""``) and its unit (the
        visible reading's where C was read, else ``unit``, the rule's under the file's reading)."""
        columns = self.visible
        if columns is None or not np.isfinite(columns.shifts[row]) or columns.picks[row] < 0:
            return "", unit
        return {1: ">=", 2: "<="}.get(int(columns.bounds[row]), ""), columns.units[columns.picks[row]]

    def subset(self, rows: np.ndarray) -> RuleHits:
        """The findings at ``rows`` (an index array or a boolean mask), level and unit kept."""
        details = None if self.details is None else np.asarray(self.details, dtype=object)[rows].tolist()
        return RuleHits(self.code, self.faces[rows], self.lines[rows], self.values[rows], self.threshold,
                        self.groups[rows], self.level, self.unit, details, self.error_above,
                        None if self.visible is None else self.visible.subset(rows))


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
        if h.visible is not None:
            limits = settings.visible_limits
            h.visible.limits = (limits.error, limits.warning, limits.min_shift)
            h.visible.fixed = h.code in settings.levels
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
                     "details": h.details, "error_above": h.error_above, "visible": _visible_meta(h.visible)}
                    for h in report.hits]
    arrays = [array for hits in report.hits for array in _hit_arrays(hits)]
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
        hits, taken = [], 0
        for h in meta.pop("hits"):
            own = dict(zip(_HIT_ARRAYS, arrays[taken : taken + len(_HIT_ARRAYS)]))
            taken += len(_HIT_ARRAYS)
            visible = h.pop("visible")
            if visible is not None:
                columns = arrays[taken : taken + len(VisibleColumns.ARRAYS)]
                taken += len(columns)
                visible = VisibleColumns(*columns, visible["textures"], visible["roles"], visible["units"],
                                         tuple(visible["limits"]), visible["fixed"])
            hits.append(RuleHits(**h, **own, visible=visible))
        prim_face_start = arrays[taken] if len(arrays) > taken else None
        return FileReport(**meta, hits=hits, prim_face_start=prim_face_start)
    except (zlib.error, KeyError, TypeError, IndexError, UnicodeDecodeError) as err:
        raise ValueError(f"not a stored report: {type(err).__name__}: {err}") from None


_HIT_ARRAYS = ("faces", "lines", "values", "groups")
_BLOB_MAGIC = b"QAR3"  # QAR2: hits carry error_above; QAR3: and Q101's visible reading


def _visible_meta(visible: VisibleColumns | None) -> dict | None:
    """The lists and settings of a visible reading, for the blob's JSON header (its arrays go after it)."""
    if visible is None:
        return None
    return {"textures": visible.textures, "roles": visible.roles, "units": visible.units,
            "limits": visible.limits, "fixed": visible.fixed}


def _hit_arrays(hits: RuleHits) -> list[np.ndarray]:
    """The arrays :func:`report_to_bytes` stores for one rule's hits: its own, then its visible reading's."""
    arrays = [getattr(hits, name) for name in _HIT_ARRAYS]
    if hits.visible is not None:
        arrays += [getattr(hits.visible, name) for name in VisibleColumns.ARRAYS]
    return arrays
