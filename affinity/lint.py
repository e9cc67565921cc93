"""Evaluate the registered rules (``affinity.rules.RULES``) on one mesh, vectorized over its quads.

Quad rules apply to quads only: triangles are always affine and have no
diagonal to split along, and n-gons are fanned by whoever renders them, so
neither is measured (both are still counted by the mesh). Every check is
``check(context) -> Measured`` (:mod:`affinity.rules.registry`): a quad rule's
runs on batches of quads (:class:`QuadBatch`), which compute what several rules
share once; a mesh rule's (Q205, Q902) on the whole mesh (:class:`WholeMesh`).
Checks measure; lint compares their values with the thresholds, on the side the
rule's ``flags`` names; rules without a threshold report 0 as their threshold.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from .attributes import ATTRIBUTES, attribute_named
from .findings import FileReport, RuleHits, settle, share_authored_geometry
from .geometry import PlanarQuads, planar_quads_by_component, squared_lengths
from .measures import split_error_by_component, split_scale
from .mesh import Mesh
from .rules import RULES, masking_rules, resolve_codes
from .settings import Settings

#: Quads measured together. Whole-mesh temporaries of a million quads spill out
#: of the caches; batches of this size keep them in, and let the batches run on
#: parallel threads.
BATCH_SIZE = 16384
#: Table values looked over (scaled, searched for NaN) together, so that the threads share a table's work.
TABLE_BLOCK = 1 << 18


class CornerTables:
    """A mesh's attribute tables and their corner indices, shared by every batch.

    Each table is kept by component, (D, V) float64 (component d of value v at
    [d, v]), so a batch gathers each component straight into its own row of the
    (D, 4, Q) layout the measures compute in; direction tables (normals) are
    scaled to unit length here, once per value rather than once per corner. A mesh
    array stored by component already (the OBJ reader's) is used as it is, not copied.
    """

    def __init__(self, mesh: Mesh):
        self.mesh = mesh
        self.corner_index = {"positions": mesh.corner_vertex,
                             **{a.field: getattr(mesh, a.corner_index) for a in ATTRIBUTES.values()}}
        self.tables: dict[str, np.ndarray | None] = {}
        self.has_nan: dict[str, bool] = {}
        self.has_absent: dict[str, bool] = {}  # some corner lacks the attribute (index -1)
        self._lacking: dict[int, bool] = {}  # id of a corner index array -> has_absent of its tables

    def prepare(self, name: str, map=map) -> None:
        """Lay table ``name`` out by component and look it over once (NaN rows mark
        missing values, index -1 a corner without one) before the batches share it.
        ``map`` runs that work over blocks of :data:`TABLE_BLOCK` values (a thread pool's
        ``map`` spreads it over the threads)."""
        if name in self.tables:
            return
        values, index = getattr(self.mesh, name), self.corner_index[name]
        if values is None or len(values) == 0 or index is None:
            self.tables[name] = None
            return
        table = np.asarray(values, dtype=np.float64).T
        blocks = [slice(start, start + TABLE_BLOCK) for start in range(0, table.shape[1], TABLE_BLOCK)]
        if name in ATTRIBUTES and ATTRIBUTES[name].unit_length:
            scaled = np.empty(table.shape)
            list(map(lambda block: _unit_length(table[:, block], scaled[:, block]), blocks))
            table = scaled
        elif table.strides[1] != table.itemsize:  # components not contiguous: laid out by component once
            table = np.ascontiguousarray(table)
        self.tables[name] = table
        self.has_nan[name] = name != "positions" and any(map(lambda block: bool(np.isnan(table[:, block]).any()),
                                                             blocks))
        if id(index) not in self._lacking:  # OBJ 'f 7/7/7' corners and OFF/PLY meshes share one index array
            self._lacking[id(index)] = len(index) > 0 and int(index.min()) < 0
        self.has_absent[name] = self._lacking[id(index)]

    def gather(self, name: str, index: np.ndarray,
               complete: bool = True) -> tuple[np.ndarray | slice, np.ndarray] | None:
        """Attribute ``name`` at the (4, Q) corners whose indices into its table are
        ``index`` (-1: the corner lacks it): ``rows`` of the quads that have it at all
        four corners (a slice when all do, or without ``complete``) and their values
        laid out by component, (D, 4, n); normals of unit length (zero ones kept).
        None when the mesh has no such attribute."""
        table = self.tables[name]
        if table is None:
            return None
        missing = None
        if self.has_absent[name]:
            missing = index < 0
            index = np.maximum(index, 0)
        values = np.empty((len(table), *index.shape))
        for component, row in zip(table, values):
            component.take(index, out=row, mode="clip")  # indices checked by the loader; clip: no buffering
        if complete and (self.has_nan[name] or (missing is not None and missing.any())):
            lacking = np.isnan(values).any(axis=(0, 1))
            if missing is not None:
                lacking |= missing.any(axis=0)
            if lacking.any():
                rows = np.flatnonzero(~lacking)
                return rows, values[:, :, rows]
        return slice(None), values


def _unit_length(table: np.ndarray, out: np.ndarray) -> None:
    """(D, V) float64 vectors laid out by component, scaled to unit length into ``out`` (D, V);
    zero ones stay zero."""
    length = np.sqrt(squared_lengths(table))
    length[length == 0] = 1.0
    np.divide(table, length, out=out)


class QuadBatch:
    """A batch of a mesh's quads, with what several rules share computed once, on demand: the context
    of a quad rule's check (``check(batch) -> Measured``, :mod:`affinity.rules.registry`).

    What a rule's check reads: ``mesh``, ``faces`` (Q,) int64 face indices in file order,
    ``corners`` (4, Q) corner indices, ``settings``, ``texture_size`` (w, h)
    texels, (2,) for all quads or (Q, 2) per quad (:meth:`texel_size`),
    ``planar`` (the quads in their own planes), ``uv`` and
    ``uv_planar`` (the quads with uv at all four corners), ``complete(name)``
    and ``split_error(rows, attrs)``.
    """

    def __init__(self, tables: CornerTables, settings: Settings, faces, corners, texture_size):
        self.tables = tables
        self.settings = settings
        self.faces = faces  # (Q,) face indices in file order
        self.corners = corners  # (4, Q) corner indices
        self.texture_size = texture_size
        self._indices = {}  # id of a corner index array -> its (4, Q) entries at the batch's corners

    def __len__(self) -> int:
        return len(self.faces)

    @property
    def mesh(self) -> Mesh:
        return self.tables.mesh

    def corner_indices(self, name: str) -> np.ndarray | None:
        """(4, Q) int64 indices into table ``name`` at the batch's corners; taken once per
        index array (OBJ ``f 7/7/7`` corners and OFF/PLY meshes share one for all tables)."""
        array = self.tables.corner_index[name]
        if array is None:
            return None
        if id(array) not in self._indices:
            self._indices[id(array)] = array.take(self.corners)
        return self._indices[id(array)]

    def take(self, rows: np.ndarray) -> QuadBatch:
        """The quads ``rows`` (n,) int64 of the batch as a batch of their own."""
        size = self.texture_size
        size = size if size is None or np.ndim(size) == 1 else np.asarray(size)[rows]
        return QuadBatch(self.tables, self.settings, self.faces[rows], self.corners[:, rows], size)

    def texel_size(self, rows) -> np.ndarray:
        """(2,) or (n, 2) float64 texel grid of the quads ``rows`` (a slice or indices into the batch)."""
        size = np.asarray(self.texture_size, dtype=np.float64)
        return size if size.ndim == 1 else size[rows]

    @cached_property
    def planar(self) -> PlanarQuads:
        return planar_quads_by_component(self.tables.gather("positions", self.corner_indices("positions"),
                                                            complete=False)[1], self.mesh.position_epsilon)

    def complete(self, name: str) -> tuple[np.ndarray | slice, np.ndarray]:
        """Quads that have attribute ``name`` at all four corners: ``rows`` (a slice
        over every quad when all have it, else indices into the batch) and the
        attribute (K, 4, n) of those quads."""
        found = self.tables.gather(name, self.corner_indices(name))
        if found is None:
            width = ATTRIBUTES[name].width if name in ATTRIBUTES else 3
            return np.zeros(0, dtype=np.int64), np.zeros((width, 4, 0))
        return found

    def split_error(self, rows, attrs: np.ndarray) -> np.ndarray:
        """(K, n) ``split_error`` of attributes (K, 4, n) of the quads ``rows``, in the
        settings' reading (``error`` or ``centre``; ``barycentric`` is uv only, so the
        other attributes read ``error`` under it)."""
        measure = self.settings.split_measure
        if isinstance(rows, slice):  # every quad: the split's scale is shared
            return split_error_by_component(self.planar, attrs, measure=measure, scale=self.split_scale)
        return split_error_by_component(self.planar.take(rows), attrs, self.settings.diagonal, measure)

    @cached_property
    def split_scale(self) -> np.ndarray:
        return split_scale(self.planar, self.settings.diagonal, self.settings.split_measure)

    @cached_property
    def uv(self) -> tuple[np.ndarray | slice, np.ndarray]:
        return self.complete("texcoords")

    @cached_property
    def uv_planar(self) -> PlanarQuads:
        return planar_quads_by_component(self.uv[1])


@dataclass(frozen=True)
class WholeMesh:
    """The context of a mesh rule's check (``check(context) -> Measured``, :mod:`affinity.rules.registry`):
    the ``mesh`` and the ``settings``; its one face is the file itself, -1 (Q205, Q902)."""

    mesh: Mesh
    settings: Settings

    @property
    def faces(self) -> np.ndarray:
        """(1,) int64: the file, as face -1."""
        return np.array([-1])


def quad_texel_grid(mesh: Mesh, settings: Settings, faces: np.ndarray | None = None):
    """Each quad's texel grid (:func:`affinity.textures.binding.texel_grid`): the size of the texture its
    material binds, from the header, else the ``texture-size`` setting."""
    from .textures.binding import texel_grid

    return texel_grid(mesh, settings.texture_size, faces)


def assumed_texture_note(size: int) -> str:
    """The remark on the first texel finding of a file whose texture is not known."""
    return (f"no texture found, texels of an assumed {size}x{size} texture "
            "(give the size with --texture-size or the texture-size setting)")


def _map_quad_batches(mesh: Mesh, settings: Settings, measure, attributes=(), grid=None) -> list:
    """Run ``measure(batch: QuadBatch)`` on every batch of the mesh's quads, in
    parallel threads (NumPy releases the GIL in its loops); results in file order.
    ``attributes`` names the tables the measure reads besides the positions; ``grid`` is the texel grid
    of the uv (:func:`quad_texel_grid`, computed here when None)."""
    tables = CornerTables(mesh)
    names = ("positions", *attributes)
    quads = np.flatnonzero(mesh.face_sizes == 4)
    if grid is None and "texcoords" in attributes:
        grid = quad_texel_grid(mesh, settings, quads)

    def run(start: int):
        faces = quads[start : start + BATCH_SIZE]
        corners = mesh.face_start[faces] + np.arange(4)[:, None]  # (4, Q): corner-major
        return measure(QuadBatch(tables, settings, faces, corners, None if grid is None else grid.of(faces)))

    starts = range(0, len(quads), BATCH_SIZE)
    if len(starts) <= 1:
        for name in names:
            tables.prepare(name)
        return [run(start) for start in starts]
    with ThreadPoolExecutor(max_workers=os.cpu_count()) as pool:
        for name in names:
            tables.prepare(name, pool.map)
        return list(pool.map(run, starts))


def lint_mesh(mesh: Mesh, settings: Settings, visible: bool = True) -> list[RuleHits]:
    """The findings of :func:`lint_pass` (without scores)."""
    return lint_pass(mesh, settings, visible).hits


def lint_pass(mesh: Mesh, settings: Settings, visible: bool = True, scores: bool = False,
              where_drawn: bool = True) -> MeshLint:
    """Apply every rule enabled by ``settings.select``/``settings.ignore`` to ``mesh``, in one pass over its quads.

    Q101 is in texels (each quad's texture size from its material's texture header,
    else ``settings.texture_size``), or the paper's dimensionless score with
    ``settings.measure == "barycentric"``; Q102 in 1/255 steps; Q103 in degrees. A
    quad is measured for an attribute only when all four corners have it. With
    ``visible``, Q101's findings on quads whose textures decode are read through them
    (C, design.md "The visible reading"; ``RuleHits.visible``). With ``scores``, the same
    pass also keeps every measured quad's value of each scored rule the mesh has an
    attribute for (:func:`scored_codes`), selected or not: the values the findings are
    those above the threshold of (before the visible reading).

    Returns
    -------
    MeshLint: ``hits``, one RuleHits per rule with at least one finding, in rule-table order, faces in
    file order within each; ``scores``, rule code -> QuadScores (empty without ``scores``).
    With ``where_drawn`` (the default), a mesh the settings draw subdivided has Q101-Q103 measured on its
    refined surface (:func:`affinity.subdivision.measured.lint_where_drawn`); without, on the faces given.
    """
    if where_drawn and settings.subdivision != "cage":  # Q101-Q103 on the surface drawn (design.md, "Subdivision")
        from .subdivision.measured import lint_where_drawn

        drawn = lint_where_drawn(mesh, settings, visible, scores, lint_pass)
        if drawn is not None:
            return MeshLint(*drawn)
    enabled = [RULES[code] for code in resolve_codes(settings.select, settings.ignore)]
    reads_textures = (visible and any(rule.visible_reading and rule.unit_for(settings.measure) == "texels"
                                      for rule in enabled)
                      and mesh.texcoords is not None and (mesh.material_maps or mesh.material_textures))
    preparing = _prepare_textures(mesh) if reads_textures else None
    hits = []
    whole = WholeMesh(mesh, settings)
    for rule in (rule for rule in enabled if rule.scope == "mesh"):
        found = rule.check(whole)
        if len(found.values):
            faces = whole.faces[found.rows]
            hits.append(RuleHits(rule.code, faces, mesh.face_line[faces] if found.lines is None else found.lines,
                                 found.values, 0.0, np.zeros(len(faces), dtype=np.int32), details=found.details))
    quad_rules = [rule for rule in enabled if rule.scope == "quad"]
    scored = [RULES[code] for code in scored_codes(mesh)] if scores else []
    thresholds = {rule.code: settings.threshold(rule.code) if rule.has_threshold else None for rule in quad_rules}

    def flag(batch: QuadBatch) -> tuple[dict, dict]:
        """Rule code -> (faces, values, breaks) of the batch's flagged quads, one finding per defect
        (:class:`Unmeasurable`), ``breaks`` (n,) bool marking the causes that took other findings' place;
        and scored rule code -> (faces, values) of every quad it measures."""
        found, measured = {}, {}
        causes = Unmeasurable(batch)
        for rule in quad_rules + [rule for rule in scored if rule not in quad_rules]:
            rows, values = _measured(batch, rule, causes, None if rule in scored else thresholds[rule.code])
            if rule in scored:
                measured[rule.code] = batch.faces[rows], values
            if rule not in quad_rules:
                continue
            threshold = thresholds[rule.code]
            if threshold is not None:
                flagged = rule.flagged(values, threshold)
                rows, values = rows[flagged], values[flagged]
            found[rule.code] = batch.faces[rows], values, causes.breaks(rule.code)[rows]
        return found, measured

    attributes = sorted({rule.attribute for rule in quad_rules + scored if rule.attribute})
    grid = quad_texel_grid(mesh, settings) if "texcoords" in attributes else None
    batches = _map_quad_batches(mesh, settings, flag, attributes, grid) if quad_rules or scored else []
    measured = {rule.code: _quad_scores(settings, rule, [found[1][rule.code] for found in batches])
                for rule in scored}
    batches = [found[0] for found in batches]
    maskable = [rule for rule in quad_rules if rule.scored and getattr(mesh, rule.attribute) is not None]
    for rule in quad_rules:
        faces = np.concatenate([found[rule.code][0] for found in batches] or [np.zeros(0, dtype=np.int64)])
        if len(faces):
            values = np.concatenate([found[rule.code][1] for found in batches])
            threshold = thresholds[rule.code]
            breaks = np.concatenate([found[rule.code][2] for found in batches])
            taken = [r.code for r in maskable if r.attribute in rule.masks]
            found = RuleHits(rule.code, faces, mesh.face_line[faces], values,
                             0.0 if threshold is None else float(threshold), mesh.face_group[faces],
                             details=_texel_details(settings, rule, faces, values, grid)
                             or _cause_details(rule, breaks, taken))
            if reads_textures and rule.visible_reading and rule.unit_for(settings.measure) == "texels":
                if preparing is not None:
                    preparing.join()
                found = _read_visible(mesh, settings, found)
            hits.append(found)
    if preparing is not None:  # no Q101 finding read it: the decode is not left running into the next file
        preparing.join()
    order = {code: i for i, code in enumerate(RULES)}
    return MeshLint(sorted(hits, key=lambda h: order[h.code]), measured)


def _measured(batch: QuadBatch, rule, causes: Unmeasurable, threshold: float | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
    """(n,) int64 rows into ``batch`` and (n,) float64 values of the quads ``rule``'s check measures; a scored
    rule leaves out the quads one of its ``causes`` takes over (one finding per defect). With a
    ``threshold``, a rule with a ``bound`` is measured only on the quads whose bound it flags there."""
    rows = np.arange(len(batch))
    if rule.bound is not None and threshold is not None:
        rows = rows[rule.flagged(rule.bound(batch), threshold)]
        batch = batch.take(rows)
    measured = rule.check(batch)
    rows, values = rows[measured.rows], measured.values
    if rule.scored:
        measured = ~causes.masked(rule)[rows]
        rows, values = rows[measured], values[measured]
    return rows, values


def mesh_report(path: str, mesh, settings, inline=(), scores: bool = False) -> FileReport:
    """The report of the file at ``path`` whose mesh is ``mesh``: its findings (lint, then :func:`settle`
    with ``settings`` and the ``inline`` ignores, then :func:`share_authored_geometry`), counts, groups,
    and for a USD stage its prims, metadata and the loader's notes; with ``scores``, every quad's scores
    from the same lint (:attr:`FileReport.scores`)."""
    linted = lint_pass(mesh, settings, scores=scores)
    hits, shared = share_authored_geometry(settle(linted.hits, settings, list(mesh.group_names), inline), mesh)
    return FileReport(path, counts=mesh.counts(), hits=hits, shared=shared, group_names=list(mesh.group_names),
                      prim_face_start=mesh.prim_face_start, up_axis=mesh.up_axis,
                      meters_per_unit=mesh.meters_per_unit,
                      notes=list(mesh.notes if linted.notes is None else linted.notes), scores=linted.scores,
                      prim_sources={prim: list(source) for prim, source in
                                    zip(mesh.group_names, mesh.prim_sources or []) if source is not None})


class Unmeasurable:
    """The quads of a batch the scored rules (Q101-Q103) do not measure: one finding per defect (design.md).

    Each rule with :attr:`~affinity.rules.Rule.masks` says where its defect takes the scored rules of those
    attributes over (:attr:`~affinity.rules.Rule.unmeasurable`): a quad whose uv collapses to a line or a point
    (Q301) gets no Q101, its value would be computed from collapsed values; a quad without area (Q201 by
    area; one repeated corner, a pole quad, is a triangle with area and keeps its findings) or a bow-tie (Q204)
    gets no Q101-Q103. The tests run whatever rules are selected, so the suppression does not depend on the
    cause being reported; each runs once per batch.
    """

    def __init__(self, batch: QuadBatch):
        self.batch = batch
        self._where: dict[str, np.ndarray] = {}

    def where(self, cause) -> np.ndarray:
        """(Q,) bool: the quads where rule ``cause``'s defect takes its masked scores over."""
        if cause.code not in self._where:
            self._where[cause.code] = np.asarray(cause.unmeasurable(self.batch), dtype=bool)
        return self._where[cause.code]

    def masked(self, rule) -> np.ndarray:
        """(Q,) bool: the quads the scored ``rule`` leaves alone."""
        masked = np.zeros(len(self.batch), dtype=bool)
        for cause in masking_rules(rule.attribute):
            masked |= self.where(cause)
        return masked

    def breaks(self, code: str) -> np.ndarray:
        """(Q,) bool: the quads where a finding of rule ``code`` takes the scored rules' place."""
        cause = RULES[code]
        return self.where(cause) if cause.masks else np.zeros(len(self.batch), dtype=bool)


def _cause_details(cause, breaks: np.ndarray, taken: list[str]) -> list | None:
    """One detail per finding of rule ``cause``: where ``breaks`` (n,) bool, what it says as a cause
    (:attr:`~affinity.rules.Rule.cause`) and the scored rules ``taken`` over (those selected whose attribute
    the mesh has, that it masks), else None; None altogether where nothing was taken over."""
    if not cause.cause or not taken or not breaks.any():
        return None
    detail = f"{cause.cause}, so {', '.join(taken)} {'is' if len(taken) == 1 else 'are'} not measured on it"
    return np.where(breaks, detail, None).tolist()


def _texel_details(settings: Settings, rule, faces: np.ndarray, values: np.ndarray, grid) -> list | None:
    """For a rule read in texels: the note on the worst finding (``faces``, ``values`` (n,), in file order)
    of a quad whose texture size was assumed (``grid``, :func:`quad_texel_grid`), None elsewhere; None
    altogether when every size is known. The worst, because every output shows it first (text and the
    capped formats order by severity) and keeps it under any cap or ``--level``."""
    if rule.unit_for(settings.measure) != "texels" or grid is None:
        return None
    assumed = np.flatnonzero(grid.assumed[faces])
    if not len(assumed):
        return None
    badness = values[assumed] if rule.worst == "lowest" else -values[assumed]
    details = [None] * len(faces)
    details[assumed[np.lexsort((faces[assumed], badness))[0]]] = assumed_texture_note(settings.texture_size)
    return details


def _prepare_textures(mesh: Mesh):
    """The background thread decoding the mesh's textures while the lint runs (None: nothing to decode)."""
    from .textures.reading import prepare_textures

    return prepare_textures(mesh)


def _read_visible(mesh: Mesh, settings: Settings, hits: RuleHits) -> RuleHits:
    """Q101's ``hits`` read through the textures their quads bind, as new hits: C replaces the shift as the
    value where a texture decodes (the shift kept in ``visible``); a texture that does not gives a note."""
    from .textures.reading import visible_reading

    found = visible_reading(mesh, settings, hits.faces, hits.values)
    if found is None:
        return hits
    columns, notes = found
    read = np.isfinite(columns.values)
    if read.any():
        hits = replace(hits, values=np.where(read, columns.values, hits.values), visible=columns)
    if notes:
        details = list(hits.details or [None] * len(hits))
        for row, note in notes.items():
            details[row] = "; ".join(filter(None, [details[row], note]))
        hits = replace(hits, details=details)
    return hits


def quad_uv_error(mesh: Mesh, diagonal: str = "02") -> tuple[np.ndarray, np.ndarray]:
    """Per-quad split error (the ``error`` reading) of the texture coordinates in uv units.

    The hybrid routes a quad whose uv quad is degenerate (Q301) by this times the
    quad's screen scale (``affinity.draw.routing``). The renderer's split is along 0-2,
    hence the default diagonal.

    Returns
    -------
    faces : (Q,) int64
        Every quad of the mesh, as a face index in file order.
    error : (Q,) float64
        |E| in uv units; NaN for quads without texture coordinates at all corners.
    """

    def measure(batch: QuadBatch) -> np.ndarray:
        error = np.full(len(batch), np.nan)
        rows, uv = batch.uv
        E = split_error_by_component(batch.planar.take(rows), uv, diagonal)
        error[rows] = np.sqrt(E[0] * E[0] + E[1] * E[1])
        return error

    faces = np.flatnonzero(mesh.face_sizes == 4)
    return faces, np.concatenate(_map_quad_batches(mesh, Settings(), measure, ("texcoords",)) or [np.zeros(0)])


@dataclass(frozen=True)
class QuadScores:
    """One affinity rule's reading for every quad that has the attribute at all four corners.

    Attributes
    ----------
    code : rule code of a scored rule (``Rule.scored``), e.g. ``"Q101"``
    attribute : the attribute as the command line names it: ``"uv"``, ``"color"`` or ``"normal"``
    unit : the values' unit under the settings' reading, e.g. ``"texels"``
    threshold : the rule flags values above it
    faces : (n,) int64, face index in file order
    values : (n,) float64, the measured score; quads the rule cannot measure
        (NaN, e.g. a missing corner attribute, or one finding per defect: :class:`Unmeasurable`) are not listed
    """

    code: str
    attribute: str
    unit: str
    threshold: float
    faces: np.ndarray
    values: np.ndarray

    @property
    def flagged(self) -> np.ndarray:
        """(n,) bool: the quads the rule flags."""
        return RULES[self.code].flagged(self.values, self.threshold)


@dataclass(frozen=True)
class MeshLint:
    """One pass of the rules over a mesh (:func:`lint_pass`): ``hits`` (list of RuleHits, rule-table order) and
    ``scores`` (scored rule code -> :class:`QuadScores` of every measured quad; empty unless asked); ``notes``
    replace the mesh's own where the pass measured a subdivided surface (None: the mesh's notes stand)."""

    hits: list[RuleHits]
    scores: dict[str, QuadScores]
    notes: list[str] | None = None


def scored_codes(mesh: Mesh | None = None, attribute: str | None = None) -> list[str]:
    """Codes of the scored rules (Q101-Q103, and any registered later), in code order: those on ``attribute``
    (named as on the command line, ``"uv"``, ``"colour"``, ...) when given, and of them those whose attribute
    ``mesh`` has when given. KeyError for an attribute no command names."""
    field = None if attribute is None else attribute_named(attribute).field
    return [code for code, rule in RULES.items() if rule.scored and field in (None, rule.attribute)
            and (mesh is None or getattr(mesh, rule.attribute) is not None)]


def _quad_scores(settings: Settings, rule, measured: list[tuple[np.ndarray, np.ndarray]]) -> QuadScores:
    """The :class:`QuadScores` of scored ``rule`` from its batches' ``measured`` (faces, values), in file order."""
    faces = np.concatenate([faces for faces, _ in measured] or [np.zeros(0, dtype=np.int64)])
    values = np.concatenate([values for _, values in measured] or [np.zeros(0)])
    return QuadScores(rule.code, ATTRIBUTES[rule.attribute].name, rule.unit_for(settings.measure),
                      settings.threshold(rule.code), faces, values)


def quad_scores(mesh: Mesh, settings: Settings, code: str) -> QuadScores:
    """Score every quad of ``mesh`` with the scored rule ``code`` alone (as ``settings`` configure it): the values
    ``affinity check`` compares with the threshold, for every quad the rule measures. No finding is made: a
    caller that also lints takes the scores from that pass (:func:`lint_pass` with ``scores``)."""
    rule = RULES[code]

    def measure(batch: QuadBatch) -> tuple[np.ndarray, np.ndarray]:
        rows, values = _measured(batch, rule, Unmeasurable(batch))
        return batch.faces[rows], values

    if getattr(mesh, rule.attribute) is None:
        return _quad_scores(settings, rule, [])
    return _quad_scores(settings, rule, _map_quad_batches(mesh, settings, measure, (rule.attribute,)))
