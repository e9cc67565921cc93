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
    lengths,
    nonplanarity,
    planar_quads,
    relative_signed_area,
)
from .imagesize import image_size
from .measures import barycentric_score, color_steps, misplacement, normal_degrees, texels
from .mesh import Mesh
from .rules import RULES, resolve_codes
from .settings import Settings

_FLAG_AT_OR_BELOW = frozenset({"Q201", "Q301"})
_ATTRIBUTE_WIDTH = {"texcoords": 2, "colors": 3, "normals": 3}


#: Quads measured together. Whole-mesh temporaries of a million quads spill out
#: of the caches; batches of this size keep them in, which measured 3-4 times
#: faster on a 1M-quad mesh, and let the batches run on parallel threads.
BATCH_SIZE = 65536


class _QuadBatch:
    """A batch of a mesh's quads, with what several rules share computed once, on demand."""

    def __init__(self, mesh: Mesh, settings: Settings, faces, corners, texture_size):
        self.mesh = mesh
        self.settings = settings
        self.faces = faces  # (Q,) face indices in file order
        self.corners = corners  # (Q, 4) corner indices
        self.texture_size = texture_size

    def __len__(self) -> int:
        return len(self.faces)

    @cached_property
    def positions(self) -> np.ndarray:
        """(Q, 4, 3) float64"""
        return self.mesh.corner_attribute("positions", self.corners)

    @cached_property
    def planar(self) -> PlanarQuads:
        return planar_quads(self.positions)

    def complete(self, name: str) -> tuple[np.ndarray | slice, np.ndarray]:
        """Quads that have attribute ``name`` at all four corners.

        Returns ``rows`` (a slice over every quad when all have it, else indices
        into the batch) and the attribute (n, 4, K) of those quads.
        """
        values = self.mesh.corner_attribute(name, self.corners)
        if values is None:
            return np.zeros(0, dtype=np.int64), np.zeros((0, 4, _ATTRIBUTE_WIDTH[name]))
        has_all = ~np.isnan(values).any(axis=(1, 2))
        if has_all.all():
            return slice(None), values
        rows = np.flatnonzero(has_all)
        return rows, values[rows]

    @cached_property
    def uv(self) -> tuple[np.ndarray | slice, np.ndarray]:
        return self.complete("texcoords")

    @cached_property
    def uv_planar(self) -> PlanarQuads:
        return planar_quads(self.uv[1])


def _map_quad_batches(mesh: Mesh, settings: Settings, measure) -> list:
    """Run ``measure(batch: _QuadBatch)`` on every batch of the mesh's quads, in
    parallel threads (NumPy releases the GIL in its loops); results in file order."""
    faces, corners = mesh.faces_of_size(4)
    size = image_size(mesh.texture_path())
    texture_size = size if size is not None else (settings.texture_size,) * 2
    starts = range(0, len(faces), BATCH_SIZE)

    def run(start: int):
        batch = slice(start, start + BATCH_SIZE)
        return measure(_QuadBatch(mesh, settings, faces[batch], corners[batch], texture_size))

    if len(starts) <= 1:
        return [run(start) for start in starts]
    with ThreadPoolExecutor(max_workers=os.cpu_count()) as pool:
        return list(pool.map(run, starts))


def _uv_disaffinity(quads: _QuadBatch) -> tuple:
    rows, uv = quads.uv
    diagonal = quads.settings.diagonal
    if quads.settings.measure == "barycentric":
        return rows, barycentric_score(quads.planar.take(rows), quads.uv_planar, diagonal)
    return rows, texels(misplacement(quads.planar.take(rows), uv, diagonal), quads.texture_size)


def _color_disaffinity(quads: _QuadBatch) -> tuple:
    rows, colors = quads.complete("colors")
    return rows, color_steps(misplacement(quads.planar.take(rows), colors, quads.settings.diagonal))


def _normal_disaffinity(quads: _QuadBatch) -> tuple:
    rows, normals = quads.complete("normals")
    length = lengths(normals)[..., None]
    unit = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    m = misplacement(quads.planar.take(rows), unit, quads.settings.diagonal)
    return rows, normal_degrees(m, unit)


def _degenerate(quads: _QuadBatch) -> tuple:
    return slice(None), degeneracy(quads.planar)


def _nonplanar(quads: _QuadBatch) -> tuple:
    return slice(None), nonplanarity(quads.positions)


def _concave(quads: _QuadBatch) -> tuple:
    rows = np.flatnonzero(~is_bowtie(quads.planar))
    return rows, interior_angles(quads.planar).max(axis=1)[rows]


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

    batches = _map_quad_batches(mesh, settings, flag)
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


def quad_uv_misplacement(mesh: Mesh, diagonal: str = "02") -> tuple[np.ndarray, np.ndarray]:
    """Per-quad misplacement of the texture coordinates in uv units, for routing.

    The hybrid renderer sends a quad to mean value coordinates when this times the
    quad's on-screen scale exceeds its pixel tolerance (design.md). The renderer's
    split is along 0-2, hence the default diagonal.

    Returns
    -------
    faces : (Q,) int64
        Every quad of the mesh, as a face index in file order.
    m : (Q,) float64
        |m| in uv units; NaN for quads without texture coordinates at all corners.
    """

    def measure(batch: _QuadBatch) -> np.ndarray:
        m = np.full(len(batch), np.nan)
        rows, uv = batch.uv
        m[rows] = lengths(misplacement(batch.planar.take(rows), uv, diagonal))
        return m

    faces, _ = mesh.faces_of_size(4)
    return faces, np.concatenate(_map_quad_batches(mesh, Settings(), measure) or [np.zeros(0)])
