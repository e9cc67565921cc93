"""Which quads ``affinity fix`` refines, to which level, and which it leaves (and why).

A quad is a candidate when a scored rule (Q101-Q103) flags it at or above the fix level.
Its level n is the smallest whose n^2 pieces (:mod:`affinity.fix.grid`) all read under
the rule's flag threshold, measured by the rule itself on the pieces (the same closed
form ``affinity check`` uses, in texels, 1/255 steps or degrees). The search starts one
below the guess of the 1/n^2 law, sqrt(value / threshold), and climbs to the cap. A
quad that needs more than the cap is left (``over-cap``: its texture wants a re-UV);
degenerate (pole quads excepted), bow-tie, nonplanar (unless ``refine_nonplanar``) and
uv-degenerate quads are left without a search. Quads keep their own levels: where two of
different levels meet, the edge carries both sets of points (:mod:`affinity.fix.layout`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..mesh import Mesh, mesh_from_polygons
from ..settings import Settings
from . import grid
from .layout import MAX_LEVEL, Layout, edge_parameters, face_patterns, layout
from .tessellate import face_polygons
from .twins import alike_across_twins, readings_from_twins, twin_faces

#: The scored rules a refinement removes.
SCORED = ("Q101", "Q102", "Q103")
#: Why a candidate is left, by the rule that says so, checked in this order.
LEFT_BY_RULE = {"Q201": "degenerate", "Q204": "bowtie", "Q202": "nonplanar", "Q301": "uv-degenerate"}
REASONS = ("over-cap", *LEFT_BY_RULE.values())
LEVEL_ORDER = ("info", "warning", "error")
#: Quads refined together when their pieces are measured: (n + 1)^2 points each.
SCORE_BATCH = 8192


@dataclass
class FixSettings:
    """How ``affinity fix`` chooses.

    Attributes
    ----------
    lint : the check's settings (thresholds, reading, diagonal, texture size, levels)
    level : the lowest level of a Q101-Q103 finding that is fixed: ``"info"``, ``"warning"``, ``"error"``
    max_refine : the largest n (n x n pieces per quad); a quad that needs more is left ``over-cap``
    faces : (k,) int64 the only faces that may be refined (a Blender selection), None: any
    refine_nonplanar : refine the quads Q202 flags too (their pieces follow the bilinear surface,
        not the split the input draws), instead of leaving them
    inline : ``(codes, faces)`` pairs of findings the file silences where they are
        (:func:`affinity.loaders.suppress.inline_ignores`): such findings are not fixed, as
        ``affinity check`` does not report them
    """

    lint: Settings = field(default_factory=Settings)
    level: str = "warning"
    max_refine: int = 8
    faces: np.ndarray | None = None
    refine_nonplanar: bool = False
    inline: list = field(default_factory=list)


@dataclass(eq=False)
class FixPlan:
    """What :func:`plan_fix` decided for one mesh (faces are 0-based, in file order, as in the check's JSON).

    Attributes
    ----------
    refine_faces : (R,) int64 quads to refine, ascending
    refine_n : (R,) int64 their level (n x n pieces)
    codes : (R,) str the rule that reads worst against its threshold on each, before
    before : (R,) float64 that rule's value on the quad
    after : (R,) float64 that rule's worst value over the quad's pieces
    units : (R,) str the unit of ``before`` and ``after``
    left_faces : (L,) int64 flagged quads left as they are, ascending
    left_reasons : (L,) str one of :data:`REASONS`
    transition_faces : (T,) int64 faces re-cut to meet the refined quads' new edge points
    faces_added : int faces in the fixed mesh minus faces in the input
    faces_added_bound : int sum of n^2 - 1 over refined quads plus 2 n per refined edge met by
        a face that is not refined (issue 41), plus 2 per point that a neighbour refined at
        another level adds to a refined quad's edge
    """

    refine_faces: np.ndarray
    refine_n: np.ndarray
    codes: np.ndarray
    before: np.ndarray
    after: np.ndarray
    units: np.ndarray
    left_faces: np.ndarray
    left_reasons: np.ndarray
    transition_faces: np.ndarray
    faces_added: int
    faces_added_bound: int

    @property
    def empty(self) -> bool:
        """Nothing to refine: the mesh is written unchanged (or not at all)."""
        return len(self.refine_faces) == 0


def flagged_quads(mesh: Mesh, fix: FixSettings) -> tuple[dict, dict]:
    """The scored findings at or above the fix level and the faces each leaving rule flags.

    Returns
    -------
    scored : code -> (faces (n,) int64, values (n,) float64) of Q101-Q103 findings at the level
    leaving : code -> faces (n,) int64 of Q201, Q202, Q204, Q301 findings
    """
    from ..findings import settle
    from ..lint import lint_mesh
    from ..rules import resolve_codes

    enabled = [code for code in resolve_codes(fix.lint.select, fix.lint.ignore) if code in SCORED]
    settings = replace(fix.lint, select=[*enabled, *LEFT_BY_RULE], ignore=[])
    hits = settle(lint_mesh(mesh, settings), settings, list(mesh.group_names), fix.inline)
    lowest = LEVEL_ORDER.index(fix.level)
    scored, leaving = {}, {}
    for h in hits:
        if h.code in SCORED:
            at_level = np.isin(h.levels(), LEVEL_ORDER[lowest:])
            scored[h.code] = h.faces[at_level], h.values[at_level]
        else:
            leaving[h.code] = h.faces
    return scored, leaving


def pole_quads(mesh: Mesh, faces: np.ndarray) -> np.ndarray:
    """(Q,) bool: which quads ``faces`` (Q,) int64 have exactly one collapsed edge (one repeated corner).

    Q201 flags them, but they are triangles in effect whose Q101-Q103 value is exact
    (design.md, "One finding per defect"), and their pieces are sound: refined, not left.
    """
    corners = mesh.positions[mesh.corner_vertex[mesh.face_start[faces, None] + np.arange(4)]]
    collapsed = (corners == np.roll(corners, -1, axis=1)).all(axis=2)
    return collapsed.sum(axis=1) == 1


def piece_scores(mesh: Mesh, faces: np.ndarray, n: int, settings: Settings, code: str) -> np.ndarray:
    """The worst value of rule ``code`` over the n x n pieces of each quad ``faces`` (Q,) int64.

    The pieces are measured by the rule itself (:func:`affinity.lint.quad_scores`), on a mesh
    made of them alone with the source's textures (so texels have the same size).

    Returns
    -------
    (Q,) float64, 0 where no piece can be measured.
    """
    from ..lint import quad_scores

    worst = np.zeros(len(faces))
    for first in range(0, len(faces), SCORE_BATCH):
        chosen = faces[first : first + SCORE_BATCH]
        corners = mesh.face_start[chosen, None] + np.arange(4)
        points = {name: None if values is None else grid.blend(values, n).reshape(-1, values.shape[-1])
                  for name in ("positions", "texcoords", "normals", "colors")
                  for values in [mesh.corner_attribute(name, corners)]}
        pieces = (grid.sub_quads(n)[None] + (n + 1) ** 2 * np.arange(len(chosen))[:, None, None]).reshape(-1, 4)
        refined = mesh_from_polygons(mesh.path, points["positions"], pieces, points["texcoords"], points["normals"],
                                     points["colors"])
        refined.material_names, refined.material_textures = mesh.material_names, mesh.material_textures
        scores = quad_scores(refined, settings, code)
        values = np.zeros(len(pieces))
        values[scores.faces] = scores.values
        worst[first : first + SCORE_BATCH] = values.reshape(len(chosen), n * n).max(axis=1)
    return worst


def needed_levels(mesh: Mesh, faces: np.ndarray, values: np.ndarray, code: str, fix: FixSettings) -> np.ndarray:
    """The smallest level n in [2, cap] at which no piece of each quad is flagged by ``code``.

    faces, values : (Q,) the flagged quads and their values. Returns (Q,) int64,
    ``max_refine + 1`` where even the cap is not enough.
    """
    from ..rules import RULES

    threshold = fix.lint.threshold(code)
    cap = fix.max_refine
    need = np.full(len(faces), cap + 1, dtype=np.int64)
    if cap < 2:
        return need
    ratio = np.divide(values, threshold, out=np.full(len(values), 4.0), where=threshold > 0)
    trial = np.clip(np.ceil(np.sqrt(np.maximum(ratio, 0))) - 1, 2, cap).astype(np.int64)
    todo = np.ones(len(faces), dtype=bool)
    for n in range(int(trial.min(initial=cap)), cap + 1):
        rows = np.flatnonzero(todo & (trial <= n))
        if len(rows) == 0:
            continue
        met = ~RULES[code].flagged(piece_scores(mesh, faces[rows], n, fix.lint, code), threshold)
        need[rows[met]] = n
        todo[rows[met]] = False
    return need


def plan_fix(mesh: Mesh, fix: FixSettings | None = None) -> FixPlan:
    """Decide which flagged quads of ``mesh`` to refine and how far (module docstring)."""
    fix = fix or FixSettings()
    if fix.level not in LEVEL_ORDER:
        raise ValueError(f"fix level must be one of {', '.join(LEVEL_ORDER)}; got {fix.level!r}")
    if not 1 <= fix.max_refine <= MAX_LEVEL:
        raise ValueError(f"max_refine must be from 1 to {MAX_LEVEL}; got {fix.max_refine}")
    scored, leaving = flagged_quads(mesh, fix)
    candidates = np.unique(np.concatenate([faces for faces, _ in scored.values()] or [np.zeros(0, np.int64)]))
    twins = twin_faces(mesh)  # USD: prims of one authored mesh get one refinement, written once
    if twins is not None:
        candidates = np.flatnonzero(np.isin(twins, twins[candidates]))
    if fix.faces is not None:
        candidates = np.intersect1d(candidates, np.asarray(fix.faces, dtype=np.int64))
    reasons = np.full(len(candidates), "", dtype=object)
    for code, reason in reversed(LEFT_BY_RULE.items()):  # the first rule in the table wins
        if not (reason == "nonplanar" and fix.refine_nonplanar):
            reasons[np.isin(candidates, leaving.get(code, []))] = reason
    reasons[(reasons == "degenerate") & pole_quads(mesh, candidates)] = ""
    need = np.zeros(len(candidates), dtype=np.int64)
    for code, (faces, values) in scored.items():
        rows = np.searchsorted(candidates, faces)
        keep = (rows < len(candidates)) & (candidates[np.minimum(rows, len(candidates) - 1)] == faces)
        keep[keep] &= reasons[rows[keep]] == ""
        need[rows[keep]] = np.maximum(need[rows[keep]], needed_levels(mesh, faces[keep], values[keep], code, fix))
    if twins is not None:
        need, reasons = alike_across_twins(twins[candidates], need, reasons)
    reasons[(reasons == "") & (need > fix.max_refine)] = "over-cap"
    refine = reasons == ""
    refine_faces = candidates[refine]
    refine_n = need[refine]
    codes, before, after, units = _readings(mesh, refine_faces, refine_n, scored, fix)
    if twins is not None:
        codes, before, after, units = readings_from_twins(twins[refine_faces], codes, before, after, units)
    placed = layout(mesh, refine_faces, refine_n)
    added, bound = _face_counts(mesh, placed, refine_faces)
    left = ~refine
    return FixPlan(refine_faces, refine_n, codes, before, after, units, candidates[left],
                   reasons[left].astype(str), placed.transition_faces, added, bound)


def _readings(mesh: Mesh, faces: np.ndarray, n: np.ndarray, scored: dict, fix: FixSettings) -> tuple:
    """Per refined quad: the rule worst against its threshold, its value before, its worst over the pieces
    at the chosen level, and its unit."""
    from ..rules import RULES

    codes = np.full(len(faces), "", dtype=object)
    before, after, worst = np.zeros(len(faces)), np.zeros(len(faces)), np.full(len(faces), -np.inf)
    for code, (flagged, values) in scored.items():
        threshold = fix.lint.threshold(code)
        rows = np.flatnonzero(np.isin(faces, flagged))
        value = values[np.searchsorted(flagged, faces[rows])]  # findings come in file order
        ratio = value / threshold if threshold > 0 else value
        better = ratio > worst[rows]
        rows, value, ratio = rows[better], value[better], ratio[better]
        codes[rows], before[rows], worst[rows] = code, value, ratio
        for level in np.unique(n[rows]):
            at = rows[n[rows] == level]
            after[at] = piece_scores(mesh, faces[at], int(level), fix.lint, code)
    units = np.array([RULES[c].unit_for(fix.lint.measure) if c else "" for c in codes], dtype=object)
    return codes.astype(str), before, after, units.astype(str)


def _face_counts(mesh: Mesh, placed: Layout, refine_faces: np.ndarray) -> tuple[int, int]:
    """Faces the refinement adds, and the bound on them (:attr:`FixPlan.faces_added_bound`)."""
    added = bound = 0
    for pattern, faces in face_patterns(mesh, placed, np.union1d(refine_faces, placed.transition_faces)):
        level, edge_levels = pattern[0], pattern[1]
        added += (len(face_polygons(*pattern)) - 1) * len(faces)
        segments = [len(edge_parameters(bits)) + 1 for bits in edge_levels]
        if level:  # n^2 - 1, and 2 per point another level adds to an edge
            bound += (level * level - 1 + 2 * sum(m - level for m in segments)) * len(faces)
        else:  # 2n per edge shared with a quad refined at level n
            bound += 2 * sum(m for m in segments if m > 1) * len(faces)
    return added, bound
