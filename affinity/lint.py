"""Evaluate the lint rules on one mesh, vectorized over its quads.

Rules Q101-Q103 and Q201-Q204, Q301-Q302 apply to quads only: triangles are
always affine and have no diagonal to split along, and n-gons are fanned by
whoever renders them, so neither is measured (both are still counted by the
mesh). Q205 applies to the whole file.

Direction of the thresholds: Q201 and Q301 (relative areas) flag values at or
below their threshold; every other thresholded rule flags values above it.
Q204, Q205 and Q302 have no threshold (reported as 0): Q204 reports the folded
fraction of the bow-tie (``affinity.geometry.folded_fraction``), Q302 the
quad's negative relative UV area, Q205 the number of vertices, on face -1 and
line 1 since no face exists to point at.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from functools import cached_property

import numpy as np

from .findings import RuleHits
from .geometry import (
    PlanarQuads,
    degeneracy,
    folded_fraction,
    interior_angles,
    is_bowtie,
    planar_quads_by_component,
    relative_signed_area,
    squared_lengths,
)
from .imagesize import image_size
from .measures import (
    barycentric_score,
    color_steps,
    normal_degrees,
    split_error_by_component,
    split_scale,
    texels,
)
from .mesh import Mesh
from .rules import RULES, resolve_codes
from .settings import Settings

_FLAG_AT_OR_BELOW = frozenset({"Q201", "Q301"})
#: The attribute each rule reads besides the positions.
_ATTRIBUTE_OF_RULE = {"Q101": "texcoords", "Q102": "colors", "Q103": "normals", "Q301": "texcoords", "Q302": "texcoords"}


#: Quads measured together. Whole-mesh temporaries of a million quads spill out
#: of the caches; batches of this size keep them in, and let the batches run on
#: parallel threads.
BATCH_SIZE = 16384


class _Tables:
    """A mesh's attribute tables and their corner indices, shared by every batch."""

    def __init__(self, mesh: Mesh):
        self.mesh = mesh
        self.corner_index = {
            "positions": mesh.corner_vertex,
            "colors": mesh.corner_vertex,
            "texcoords": mesh.corner_texcoord,
            "normals": mesh.corner_normal,
        }
        self.tables: dict[str, np.ndarray | None] = {}
        self.has_nan: dict[str, bool] = {}

    def prepare(self, name: str) -> None:
        """Look table ``name`` over once (NaN rows mark missing values) before the batches share it."""
        if name in self.tables:
            return
        values = getattr(self.mesh, name)
        if values is None or len(values) == 0 or self.corner_index[name] is None:
            self.tables[name] = None
            return
        self.tables[name] = np.asarray(values, dtype=np.float64)
        self.has_nan[name] = name != "positions" and bool(np.isnan(self.tables[name]).any())

    def gather(self, name: str, corners: np.ndarray, complete: bool = True) -> tuple[np.ndarray | slice, np.ndarray] | None:
        """Attribute ``name`` at the (4, Q) corners: ``rows`` of the quads that have
        it at all four corners (a slice when all do, or without ``complete``) and
        their values laid out by component, (D, 4, n); normals scaled to unit
        length (zero ones kept). None when the mesh has no such attribute."""
        table = self.tables[name]
        if table is None:
            return None
        index = self.corner_index[name][corners]
        missing = index < 0
        np.maximum(index, 0, out=index)
        values = np.ascontiguousarray(np.transpose(table.take(index, axis=0), (2, 0, 1)))
        if name == "normals":
            length = np.sqrt(squared_lengths(values))
            np.divide(values, length, out=values, where=length > 0)
        if complete and (self.has_nan[name] or missing.any()):
            has_all = ~(missing.any(axis=0) | np.isnan(values).any(axis=(0, 1)))
            if not has_all.all():
                rows = np.flatnonzero(has_all)
                return rows, values[:, :, rows]
        return slice(None), values


class _QuadBatch:
    """A batch of a mesh's quads, with what several rules share computed once, on demand."""

    def __init__(self, tables: _Tables, settings: Settings, faces, corners, texture_size):
        self.tables = tables
        self.settings = settings
        self.faces = faces  # (Q,) face indices in file order
        self.corners = corners  # (4, Q) corner indices
        self.texture_size = texture_size

    def __len__(self) -> int:
        return len(self.faces)

    @cached_property
    def planar(self) -> PlanarQuads:
        return planar_quads_by_component(self.tables.gather("positions", self.corners, complete=False)[1])

    def complete(self, name: str) -> tuple[np.ndarray | slice, np.ndarray]:
        """Quads that have attribute ``name`` at all four corners: ``rows`` (a slice
        over every quad when all have it, else indices into the batch) and the
        attribute (K, 4, n) of those quads."""
        found = self.tables.gather(name, self.corners)
        if found is None:
            width = {"texcoords": 2}.get(name, 3)
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


def _map_quad_batches(mesh: Mesh, settings: Settings, measure, attributes=()) -> list:
    """Run ``measure(batch: _QuadBatch)`` on every batch of the mesh's quads, in
    parallel threads (NumPy releases the GIL in its loops); results in file order.
    ``attributes`` names the tables the measure reads besides the positions."""
    tables = _Tables(mesh)
    for name in ("positions", *attributes):
        tables.prepare(name)
    size = image_size(mesh.texture_path()) if "texcoords" in attributes else None
    texture_size = size if size is not None else (settings.texture_size,) * 2
    quads = np.flatnonzero(mesh.face_sizes == 4)

    def run(start: int):
        faces = quads[start : start + BATCH_SIZE]
        corners = mesh.face_start[faces] + np.arange(4)[:, None]  # (4, Q): corner-major
        return measure(_QuadBatch(tables, settings, faces, corners, texture_size))

    starts = range(0, len(quads), BATCH_SIZE)
    if len(starts) <= 1:
        return [run(start) for start in starts]
    with ThreadPoolExecutor(max_workers=os.cpu_count()) as pool:
        return list(pool.map(run, starts))


def _uv_disaffinity(quads: _QuadBatch) -> tuple:
    rows, uv = quads.uv
    diagonal = quads.settings.diagonal
    if quads.settings.measure == "barycentric":
        return rows, barycentric_score(quads.planar.take(rows), quads.uv_planar, diagonal)
    return rows, texels(quads.split_error(rows, uv).T, quads.texture_size)


def _color_disaffinity(quads: _QuadBatch) -> tuple:
    rows, colors = quads.complete("colors")
    return rows, color_steps(quads.split_error(rows, colors).T)


def _normal_disaffinity(quads: _QuadBatch) -> tuple:
    rows, unit = quads.complete("normals")  # unit length already (see _Tables.gather)
    m = quads.split_error(rows, unit)
    # The angle atan2(|m|, |mean normal|) exceeds the threshold only where
    # |m| > tan(threshold) |mean normal|: the arctangent is taken for those only.
    threshold = quads.settings.threshold("Q103")
    picked = slice(None)
    if 0 <= threshold < 89:  # a negative threshold (every value wanted) picks every quad
        m_length = np.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
        mean = unit.sum(axis=1)
        mean_length = np.sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]) / 4
        picked = np.flatnonzero(m_length >= mean_length * (np.tan(np.radians(threshold)) * (1 - 1e-9)))
    rows = np.arange(len(quads))[rows][picked]
    degrees = normal_degrees(m.T[picked], np.transpose(unit, (2, 1, 0))[picked])
    return rows, degrees


def _degenerate(quads: _QuadBatch) -> tuple:
    return slice(None), degeneracy(quads.planar)


def _nonplanar(quads: _QuadBatch) -> tuple:
    return slice(None), quads.planar.warp


def _concave(quads: _QuadBatch) -> tuple:
    planar = quads.planar
    candidates = ~is_bowtie(planar)
    if quads.settings.threshold("Q203") >= 180:
        # An angle above 180 degrees needs a clockwise turn; half the tolerance
        # keeps every turn interior_angles could read as one.
        candidates &= (planar.areas < -0.5 * planar.tolerance[:, None]).any(axis=1)
    rows = np.flatnonzero(candidates)
    if len(rows) == 0:
        return rows, np.zeros(0)
    return rows, interior_angles(planar.take(rows)).max(axis=1)


def _bowtie(quads: _QuadBatch) -> tuple:
    rows = np.flatnonzero(is_bowtie(quads.planar))
    return rows, folded_fraction(quads.planar.take(rows))


def _uv_degenerate(quads: _QuadBatch) -> tuple:
    return quads.uv[0], np.abs(relative_signed_area(quads.uv_planar))


def _uv_flipped(quads: _QuadBatch) -> tuple:
    rows = np.arange(len(quads))[quads.uv[0]]
    area = relative_signed_area(quads.uv_planar)
    flipped = area < -RULES["Q301"].default_threshold
    return rows[flipped], area[flipped]


# Each returns (rows of the batch: indices or a slice, values of those rows); rules
# without a threshold return only the rows they flag.
_QUAD_RULES = {
    "Q101": _uv_disaffinity,
    "Q102": _color_disaffinity,
    "Q103": _normal_disaffinity,
    "Q201": _degenerate,
    "Q202": _nonplanar,
    "Q203": _concave,
    "Q204": _bowtie,
    "Q301": _uv_degenerate,
    "Q302": _uv_flipped,
}


def lint_mesh(mesh: Mesh, settings: Settings) -> list[RuleHits]:
    """Apply every rule enabled by ``settings.select``/``settings.ignore`` to ``mesh``.

    Q101 is in texels (texture size from ``mesh.texture_path()`` when that image
    is readable, else ``settings.texture_size``), or the paper's dimensionless score
    with ``settings.measure == "barycentric"``; Q102 in 1/255 steps; Q103 in
    degrees. A quad is measured for an attribute only when all four corners have it.

    Returns
    -------
    list of RuleHits, one per rule with at least one finding, in rule-table order;
    faces in file order within each.
    """
    enabled = resolve_codes(settings.select, settings.ignore)
    hits = []
    if "Q205" in enabled and mesh.n_faces == 0 and len(mesh.positions) > 0:
        hits.append(
            RuleHits("Q205", np.array([-1]), np.array([1]), np.array([float(len(mesh.positions))]),
                     0.0, np.zeros(1, dtype=np.int32))
        )
    codes = [code for code in enabled if code in _QUAD_RULES]
    thresholds = {
        code: settings.threshold(code) if RULES[code].default_threshold is not None else None
        for code in codes
    }

    def flag(batch: _QuadBatch) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Rule code -> (faces, values) of the batch's flagged quads."""
        found = {}
        for code in codes:
            rows, values = _QUAD_RULES[code](batch)
            faces = batch.faces[rows]
            threshold = thresholds[code]
            if threshold is not None:
                flagged = values <= threshold if code in _FLAG_AT_OR_BELOW else values > threshold
                faces, values = faces[flagged], values[flagged]
            found[code] = faces, values
        return found

    attributes = sorted({_ATTRIBUTE_OF_RULE[code] for code in codes if code in _ATTRIBUTE_OF_RULE})
    batches = _map_quad_batches(mesh, settings, flag, attributes) if codes else []
    for code in codes:
        faces = np.concatenate([found[code][0] for found in batches] or [np.zeros(0, dtype=np.int64)])
        if len(faces):
            values = np.concatenate([found[code][1] for found in batches])
            threshold = thresholds[code]
            hits.append(
                RuleHits(code, faces, mesh.face_line[faces], values,
                         0.0 if threshold is None else float(threshold), mesh.face_group[faces])
            )
    return hits


def quad_uv_error(mesh: Mesh, diagonal: str = "02") -> tuple[np.ndarray, np.ndarray]:
    """Per-quad split error (the ``error`` reading) of the texture coordinates in uv units.

    The hybrid routes a quad whose uv quad is degenerate (Q301) by this times the
    quad's screen scale (``affinity.routing``). The renderer's split is along 0-2,
    hence the default diagonal.

    Returns
    -------
    faces : (Q,) int64
        Every quad of the mesh, as a face index in file order.
    error : (Q,) float64
        |E| in uv units; NaN for quads without texture coordinates at all corners.
    """

    def measure(batch: _QuadBatch) -> np.ndarray:
        error = np.full(len(batch), np.nan)
        rows, uv = batch.uv
        E = split_error_by_component(batch.planar.take(rows), uv, diagonal)
        error[rows] = np.sqrt(E[0] * E[0] + E[1] * E[1])
        return error

    faces = np.flatnonzero(mesh.face_sizes == 4)
    return faces, np.concatenate(_map_quad_batches(mesh, Settings(), measure, ("texcoords",)) or [np.zeros(0)])
