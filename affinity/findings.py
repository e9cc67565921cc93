"""Lint results, kept as arrays per rule so a million findings cost no Python objects."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
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

    def read(self) -> np.ndarray:
        """(n,) bool: the findings whose value is C, read through a texture (its shift known, a texture picked)."""
        return (self.picks >= 0) & np.isfinite(self.shifts)

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
class RefinedColumns:
    """Where a rule's n findings were measured on a subdivided surface (design.md, "Subdivision"): each
    finding is its base face's worst refined face.

    Attributes
    ----------
    levels : (n,) int8, the subdivision level measured (0: the cage)
    flagged : (n,) int32, the base face's refined faces the rule flags
    measured : (n,) int32, the base face's refined faces
    """

    levels: np.ndarray
    flagged: np.ndarray
    measured: np.ndarray

    ARRAYS = ("levels", "flagged", "measured")

    def subset(self, rows: np.ndarray) -> RefinedColumns:
        return RefinedColumns(*(getattr(self, name)[rows] for name in self.ARRAYS))


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
    refined : RefinedColumns or None
        Where the findings were measured on a subdivided surface (None: on the cage).
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
    refined: RefinedColumns | None = None

    def __len__(self) -> int:
        return len(self.faces)

    def levels(self) -> np.ndarray:
        """(n,) str: the level of each finding (``error`` above ``error_above``, else ``level``)."""
        from .rules import LEVELS

        return np.asarray(LEVELS)[self.level_ranks()]

    def level_ranks(self) -> np.ndarray:
        """(n,) int8: each finding's level as its index in ``LEVELS`` (0 ``error``, 1 ``warning``, 2 ``info``);
        where the visible reading read C, its level (design.md, "The visible reading")."""
        from .rules import LEVELS, RULES

        rank = np.full(len(self), LEVELS.index(self.level or RULES[self.code].level), dtype=np.int8)
        if self.error_above is not None:
            rank[self.values > self.error_above] = 0
        if self.visible is not None:
            visible = self.visible.levels()
            for index, level in enumerate(LEVELS):
                rank[visible == level] = index
        return rank

    @property
    def shifts(self) -> np.ndarray:
        """(n,) float64: what the rule measured against ``threshold``, in ``unit`` (Q101: the split's shift in
        texels): ``values`` where no texture was read, the visible reading's shift where ``values`` hold C.
        Consumers that need the shift (fix, the texel unit) read this column, never ``values``."""
        if self.visible is None:
            return self.values
        return np.where(self.visible.read(), self.visible.shifts, self.values)

    def units(self) -> np.ndarray:
        """(n,) str (object): the unit of each of ``values``: the texture's (``1/255``, ``degrees``) where C was
        read, else ``unit`` (the rule's under the file's reading; set by :func:`settle`)."""
        from .rules import RULES

        units = np.full(len(self), self.unit or RULES[self.code].unit, dtype=object)
        if self.visible is not None:
            read = self.visible.read()
            units[read] = np.asarray(self.visible.units, dtype=object)[self.visible.picks[read]]
        return units

    def thresholds(self) -> np.ndarray:
        """(n,) float64: the threshold each of ``values`` is read against, in its own unit: ``threshold``, or
        visible-warning where C was read (as every format writes the finding's ``threshold``)."""
        thresholds = np.full(len(self), float(self.threshold))
        if self.visible is not None:
            thresholds[self.visible.read()] = self.visible.limits[1]
        return thresholds

    def ratios(self) -> np.ndarray:
        """(n,) float64: how far each value is beyond its own threshold (:meth:`thresholds`), as a ratio, worse
        the larger: value / threshold for a rule that flags above, threshold / value for one that flags at or
        below (inf at 0); NaN for a rule without a threshold. One unit for every row, so findings read in
        texels and in 1/255 steps rank together (output order, report places, Blender's worst)."""
        from .rules import RULES

        rule = RULES[self.code]
        if not rule.has_threshold:
            return np.full(len(self), np.nan)
        thresholds = self.thresholds()
        with np.errstate(divide="ignore", invalid="ignore"):
            if rule.flags == "above":
                return np.where(thresholds > 0, self.values / thresholds, np.inf * np.sign(self.values))
            return np.where(self.values > 0, thresholds / self.values, np.inf)

    @property
    def ranked_by_ratio(self) -> bool:
        """Whether the findings rank by :meth:`ratios`: the rule flags values above a positive threshold."""
        from .rules import RULES

        rule = RULES[self.code]
        return rule.flags == "above" and rule.has_threshold and self.threshold > 0

    def worst_key(self) -> np.ndarray:
        """(n,) float64, lowest the worst: minus :meth:`ratios` where the findings rank by them, else the values
        from the rule's ``worst`` end (a rule without a threshold, or one that flags at or below it)."""
        from .rules import RULES

        if self.ranked_by_ratio:
            return -self.ratios()
        return self.values if RULES[self.code].worst == "lowest" else -self.values

    def at_or_above(self, level: str) -> RuleHits:
        """The findings at ``level`` or worse (``error`` > ``warning`` > ``info``)."""
        from .rules import LEVELS

        return self.subset(self.level_ranks() <= LEVELS.index(level))

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
                        None if self.visible is None else self.visible.subset(rows),
                        None if self.refined is None else self.refined.subset(rows))


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

    ``shared`` (USD) has one entry per mesh whose points and topology several prims
    take from one layer (:func:`share_authored_geometry`): ``prim`` (the first of
    them, whose group holds the findings), ``layer`` and ``layer_prim`` (where the
    geometry is authored), ``prims`` (every prim that references it) and
    ``values``: per rule code, ``[face within the prim, [value per prim, None where
    that prim has no finding]]`` for the findings whose prims disagree (different
    textures bound).

    ``prim_sources`` (USD) maps each mesh prim whose geometry's source is known to ``[layer, prim path in
    it]`` (:func:`affinity.loaders.usdlayers.geometry_source`): a run keeps one report per authored mesh
    (:func:`affinity.pipeline.authored.one_report_per_authored_mesh`).

    ``scores`` (only when asked, for the report: never stored) maps each scored rule the mesh has an
    attribute for to the :class:`affinity.lint.QuadScores` of every quad it measures, from the same lint.
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
    shared: list[dict] = field(default_factory=list)
    scores: dict = field(default_factory=dict)
    prim_sources: dict[str, list[str]] = field(default_factory=dict)

    @property
    def n_findings(self) -> int:
        return sum(len(h) for h in self.hits)


def _matches(code: str, prefixes: list[str]) -> bool:
    return any(p == "ALL" or code.startswith(p) for p in prefixes)


def settle(hits: list[RuleHits], settings, group_names: list[str], inline=()) -> list[RuleHits]:
    """Lint's ``hits`` with their level, visibility threshold and unit from ``settings``, the suppressed
    ones dropped: new records, ``hits`` are left as they are.

    Suppressed are the findings in a group that a ``path::group`` per-file
    ignore names (``settings.group_ignores``: glob over ``group_names``) and the
    faces ``inline`` silences: ``(codes, faces (k,) int64)`` pairs from
    ``# affinity: ignore[CODE]`` comments (:mod:`affinity.loaders.suppress`).
    """
    from .rules import RULES

    limits = settings.visible_limits
    settled = []
    for h in hits:
        visible = h.visible and replace(h.visible, limits=(limits.error, limits.warning, limits.min_shift),
                                        fixed=h.code in settings.levels)
        h = replace(h, level=settings.level(h.code), unit=h.unit or RULES[h.code].unit_for(settings.measure),
                    error_above=settings.error_above(h.code), visible=visible)
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


def share_authored_geometry(hits: list[RuleHits], mesh) -> tuple[list[RuleHits], list[dict]]:
    """Findings of a USD stage reported once where the geometry is authored.

    Mesh prims whose points and topology come from one layer (the same
    ``mesh.prim_sources`` entry, the same number of faces) are one mesh: their
    findings move to the first of them (faces renumbered into its faces), each
    (rule, face) keeping its worst value over the prims (:meth:`RuleHits.worst_key`: each against its own threshold).
    Returns the hits and the :attr:`FileReport.shared` entries; a mesh of other
    formats, or a stage without shared geometry, comes back as it was.

    Vectorized per rule: ``owner`` (P,) maps each prim to the first prim of its
    source, ``shift`` (P,) moves its faces onto that prim's.
    """
    sources = mesh.prim_sources
    if not sources or len(sources) < 2:
        return hits, []
    starts = mesh.prim_face_start
    sizes = np.diff(starts)
    first: dict = {}
    owner = np.array([first.setdefault((source, int(n)), p) if source is not None else p
                      for p, (source, n) in enumerate(zip(sources, sizes))])
    if (owner == np.arange(len(owner))).all():
        return hits, []
    shift = starts[owner] - starts[:-1]
    by_owner = np.argsort(owner, kind="stable")
    same_source = np.split(by_owner, np.flatnonzero(np.diff(owner[by_owner])) + 1)
    members = {int(owner[g[0]]): g.tolist() for g in same_source if len(g) > 1}  # first prim -> its prims, rising
    shared = [{"prim": mesh.group_names[o], "layer": sources[o][0], "layer_prim": sources[o][1],
               "prims": [mesh.group_names[p] for p in prims], "values": {}} for o, prims in members.items()]
    entry_of = {o: entry for o, entry in zip(members, shared)}
    merged = []
    for h in hits:
        on_face = h.faces >= 0  # file-level findings (face -1) stay as they are
        prim = h.groups.astype(np.int64)
        faces = np.where(on_face, h.faces + shift[prim], h.faces)
        groups = np.where(on_face, owner[prim], prim).astype(h.groups.dtype)
        order = np.lexsort((h.worst_key(), faces, ~on_face))
        keep = order[np.concatenate(([True], (faces[order][1:] != faces[order][:-1]) | ~on_face[order][1:]))]
        keep.sort()
        out = h.subset(keep)
        out.faces, out.groups = faces[keep], groups[keep]
        for o, values in prim_values(h, faces, prim, owner, starts, members).items():
            entry_of[o]["values"][h.code] = values
        merged.append(out)
    return merged, shared


def prim_values(h: RuleHits, faces, prim, owner, starts, members) -> dict[int, list]:
    """First prim of a shared mesh -> the faces of rule ``h`` whose prims measured differently there, as
    :attr:`FileReport.shared` keeps them: ``[face within the prim, [value per prim, None where none]]``.

    One (faces of the mesh, its prims) table per shared mesh with findings, NaN where a prim has none.
    """
    found = {}
    rows = np.flatnonzero(np.isin(owner[prim], list(members)) & (h.faces >= 0))
    rows = rows[np.argsort(owner[prim[rows]], kind="stable")]
    for chunk in np.split(rows, np.flatnonzero(np.diff(owner[prim[rows]])) + 1) if len(rows) else []:
        o = int(owner[prim[chunk[0]]])
        prims = members[o]
        table = np.full((starts[o + 1] - starts[o], len(prims)), np.nan)
        table[faces[chunk] - starts[o], np.searchsorted(prims, prim[chunk])] = h.values[chunk]
        agree = np.isclose(table, table[:, :1], rtol=1e-6, atol=0, equal_nan=True).all(axis=1)
        differ = np.flatnonzero(~np.isnan(table).all(axis=1) & ~agree)
        if len(differ):
            found[o] = [[int(face), [None if np.isnan(v) else float(v) for v in table[face]]] for face in differ]
    return found


def report_to_bytes(report: FileReport) -> bytes:
    """``report`` as a compact blob: a JSON header (fields, then each array's dtype and shape) and the
    arrays' raw bytes, zlib-compressed.

    :func:`report_from_bytes` gives back an equal report (same dtypes, same
    values bit for bit), without pickle, so a damaged blob can only fail to load.
    """
    import json
    import zlib
    from dataclasses import fields

    kept_apart = ("hits", "prim_face_start", "scores")  # scores are the report's, never stored
    meta = {f.name: getattr(report, f.name) for f in fields(report) if f.name not in kept_apart}
    meta["hits"] = [{"code": h.code, "threshold": h.threshold, "level": h.level, "unit": h.unit,
                     "details": h.details, "error_above": h.error_above, "visible": _visible_meta(h.visible),
                     "refined": h.refined is not None}
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
    """The report :func:`report_to_bytes` stored; anything else (a damaged blob, a value that is not
    bytes) raises ValueError."""
    import json
    import math
    import zlib

    try:
        if not isinstance(data, bytes) or not data.startswith(_BLOB_MAGIC):
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
            refined = None
            if h.pop("refined"):
                refined = RefinedColumns(*arrays[taken : taken + len(RefinedColumns.ARRAYS)])
                taken += len(RefinedColumns.ARRAYS)
            hits.append(RuleHits(**h, **own, visible=visible, refined=refined))
        prim_face_start = arrays[taken] if len(arrays) > taken else None
        return FileReport(**meta, hits=hits, prim_face_start=prim_face_start)
    except (zlib.error, KeyError, TypeError, IndexError, AttributeError) as err:
        raise ValueError(f"not a stored report: {type(err).__name__}: {err}") from None


_HIT_ARRAYS = ("faces", "lines", "values", "groups")
_BLOB_MAGIC = b"QAR4"  # QAR2: hits carry error_above; QAR3: and Q101's visible reading; QAR4: and subdivision


def _visible_meta(visible: VisibleColumns | None) -> dict | None:
    """The lists and settings of a visible reading, for the blob's JSON header (its arrays go after it)."""
    if visible is None:
        return None
    return {"textures": visible.textures, "roles": visible.roles, "units": visible.units,
            "limits": visible.limits, "fixed": visible.fixed}


def _hit_arrays(hits: RuleHits) -> list[np.ndarray]:
    """The arrays :func:`report_to_bytes` stores for one rule's hits: its own, its visible reading's, then where
    it was refined."""
    arrays = [getattr(hits, name) for name in _HIT_ARRAYS]
    if hits.visible is not None:
        arrays += [getattr(hits.visible, name) for name in VisibleColumns.ARRAYS]
    if hits.refined is not None:
        arrays += [getattr(hits.refined, name) for name in RefinedColumns.ARRAYS]
    return arrays
