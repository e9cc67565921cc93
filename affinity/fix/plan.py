"""Which quads ``affinity fix`` refines, to which level, and which it leaves (and why).

A quad is a candidate when a scored rule (Q101-Q103) flags it at or above the fix level.
Its level n is the smallest odd n whose n^2 pieces (:mod:`affinity.fix.grid`) all read under
the rule's flag threshold, measured by the rule itself on the pieces (the same closed form
``affinity check`` uses, in texels, 1/255 steps or degrees; for uv the split's *shift* in
texels, never the visible reading C in 1/255 steps, which only grades it). Levels are odd
so every quad beside a refined one closes with quads (:mod:`affinity.fix.layout`); the cap
is the smallest odd number at or above ``max_refine``. The search starts one below the
guess of the 1/n^2 law, sqrt(value / threshold), and climbs to the cap.

Left as they are (:data:`REASONS`): quads that need more than the cap (``over-cap``: the
texture wants a re-UV), degenerate (pole quads excepted), bow-tie, nonplanar (unless
``refine_nonplanar``) and uv-degenerate quads; every candidate under a profile that draws the
subdivided surface (``subdivided``); what the output budget does not reach, the least bad
first (``over-budget``); and what the re-check of the result still flags (``still-flagged``,
:mod:`affinity.fix.verify`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..mesh import Mesh
from ..rules import LEVELS
from ..settings import Settings
from .twins import alike_across_twins, twin_faces


def left_by_rule() -> dict[str, str]:
    """Why a candidate is left, by the rule that says so (:attr:`affinity.rules.Rule.fix_leaves`), checked in
    this order."""
    from ..rules import fix_left_rules

    return {rule.code: rule.fix_leaves for rule in fix_left_rules()}


def uncut_by_rule() -> tuple[str, ...]:
    """The rules whose quads beside a refinement are never cut (:attr:`affinity.rules.Rule.fix_uncut`): a cut of
    their bilinear patch would fold, so they stay as they are and the refined quad closes to them."""
    from ..rules import fix_uncut_rules

    return tuple(rule.code for rule in fix_uncut_rules())


REASONS = ("over-cap", *left_by_rule().values(), "subdivided", "still-flagged", "over-budget")
LEVEL_ORDER = tuple(reversed(LEVELS))  # the mildest first
#: Quads refined together when their pieces are measured: (n + 1)^2 points each.
SCORE_BATCH = 8192
#: The default output budget: faces added, and bytes added to the written file (an estimate).
MAX_FACES_ADDED = 2_000_000
MAX_BYTES_ADDED = 256 * 2**20


@dataclass
class FixSettings:
    """How ``affinity fix`` chooses.

    Attributes
    ----------
    lint : the check's settings (thresholds, reading, diagonal, texture size, levels)
    level : the lowest level of a Q101-Q103 finding that is fixed: ``"info"``, ``"warning"``, ``"error"``
    max_refine : the largest n asked for (n x n pieces per quad); the cap is the smallest odd number at or
        above it, and a quad that needs more is left ``over-cap``
    faces : (k,) int64 the only faces that may be refined (a Blender selection), None: any
    refine_nonplanar : refine the quads Q202 flags too (their pieces follow the bilinear surface,
        not the split the input draws), instead of leaving them
    inline : ``(codes, faces)`` pairs of findings the file silences where they are
        (:func:`affinity.loaders.suppress.inline_ignores`): such findings are not fixed, as
        ``affinity check`` does not report them
    subdivided : the check draws the subdivided surface (a profile that subdivides): every candidate is
        left ``subdivided``, the crease there being the subdivision-aware measure's business. The one hook
        for the profile setting (:func:`profile_subdivides`).
    max_faces_added, max_bytes_added : the output budget (faces, and an estimate of the bytes written)
    verify_rounds : re-checks of the result; a face still flagged is left as it was and the rest re-built
    """

    lint: Settings = field(default_factory=Settings)
    level: str = "warning"
    max_refine: int = 9
    faces: np.ndarray | None = None
    refine_nonplanar: bool = False
    inline: list = field(default_factory=list)
    subdivided: bool = False
    max_faces_added: int = MAX_FACES_ADDED
    max_bytes_added: int = MAX_BYTES_ADDED
    verify_rounds: int = 3

    @property
    def cap(self) -> int:
        """The highest level: the smallest odd number at or above ``max_refine``."""
        return self.max_refine | 1


#: Profiles that draw the subdivided surface of a mesh whose scheme subdivides (design.md, "Subdivision").
def profile_subdivides(settings: Settings, scheme_subdivides: bool = True) -> bool:
    """Whether ``settings`` check the subdivided surface rather than the cage (a level above 0 or the limit,
    :meth:`~affinity.settings.Settings.subdivision_level`) for a mesh whose own scheme subdivides or not
    (``scheme_subdivides``: a USD mesh; OBJ, PLY and OFF have no scheme). Then the fix leaves its
    candidates ``subdivided``: what you check is what you fix."""
    return settings.subdivision_level(scheme_subdivides) != 0


@dataclass(eq=False)
class FixPlan:
    """What :func:`plan_fix` decided for one mesh (faces are 0-based, in file order, as in the check's JSON).

    Attributes
    ----------
    refine_faces : (R,) int64 quads to refine, ascending
    refine_n : (R,) int64 their level (odd)
    codes : (R,) str the rule that reads worst against its threshold on each, before
    before : (R,) float64 that rule's value on the quad (uv: the shift, texels)
    after : (R,) float64 that rule's worst value over the quad's grid pieces
    units : (R,) str the unit of ``before`` and ``after``
    left_faces : (L,) int64 flagged quads left as they are, ascending
    left_reasons : (L,) str one of :data:`REASONS`
    transition_faces : (T,) int64 faces not refined that are cut to meet the refined quads' edge points
    faces_added : int faces in the fixed mesh minus faces in the input (exact)
    faces_added_bound : int the output budget's face limit the plan kept to
    bytes_added : int an estimate of the bytes the written file grows by
    frozen_faces : (k,) int64 faces never cut: the left quads and the quads a cut would fold
    still_flagged : (s,) int64 faces the re-check still flags at the fix level (left ``still-flagged``)
    new_findings : list of ``{"code", "face"}``: findings of other rules at warning or above on new faces
        whose input face had none of that rule (the result is written only when allowed)
    refined : the fixed mesh (:class:`affinity.fix.apply.Refined`) the re-check read, None before
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
    bytes_added: int = 0
    frozen_faces: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    still_flagged: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    new_findings: list = field(default_factory=list)
    refined: object = None

    @property
    def empty(self) -> bool:
        """Nothing to refine: the mesh is written unchanged (or not at all)."""
        return len(self.refine_faces) == 0


def flagged_quads(mesh: Mesh, fix: FixSettings) -> tuple[dict, dict]:
    """The scored findings at or above the fix level and the faces each leaving rule flags.

    Returns
    -------
    scored : code -> (faces (n,) int64, values (n,) float64) of Q101-Q103 findings at the level, values
        in the rule's measure (:attr:`~affinity.findings.RuleHits.shifts`: Q101's shift, never C)
    leaving : code -> faces (n,) int64 of the findings of :func:`left_by_rule` and :func:`uncut_by_rule`
    """
    from ..findings import settle
    from ..lint import lint_mesh, scored_codes
    from ..rules import resolve_codes

    removed = scored_codes()  # the scored rules a refinement removes
    enabled = [code for code in resolve_codes(fix.lint.select, fix.lint.ignore) if code in removed]
    settings = replace(fix.lint, select=[*enabled, *left_by_rule(), *uncut_by_rule()], ignore=[])
    hits = settle(lint_mesh(mesh, settings), settings, list(mesh.group_names), fix.inline)
    lowest = LEVEL_ORDER.index(fix.level)
    scored, leaving = {}, {}
    for h in hits:
        if h.code in removed:
            at_level = np.isin(h.levels(), LEVEL_ORDER[lowest:])
            scored[h.code] = h.faces[at_level], h.shifts[at_level]
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


def quads_alone(mesh: Mesh, faces: np.ndarray) -> Mesh:
    """The quads ``faces`` (Q,) int64 of ``mesh`` as a mesh of their own: their corners' values only (tables
    compacted), their materials, lines and groups; quads adjacent in ``mesh`` stay adjacent."""
    corners = (mesh.face_start[faces, None] + np.arange(4)).reshape(-1)

    def compact(values, index):
        if values is None or index is None:
            return values, None
        used, local = np.unique(index[corners], return_inverse=True)
        missing = used < 0
        return values[used[~missing]], np.where(missing[local], -1, local - missing.sum()).reshape(-1)

    positions, corner_vertex = compact(mesh.positions, mesh.corner_vertex)
    used_vertices = np.unique(mesh.corner_vertex[corners])
    texcoords, corner_texcoord = compact(mesh.texcoords, mesh.corner_texcoord)
    normals, corner_normal = compact(mesh.normals, mesh.corner_normal)
    return replace(mesh, positions=positions, colors=None if mesh.colors is None else mesh.colors[used_vertices],
                   face_start=4 * np.arange(len(faces) + 1, dtype=np.int64), corner_vertex=corner_vertex,
                   texcoords=texcoords, corner_texcoord=corner_texcoord, normals=normals, corner_normal=corner_normal,
                   face_line=mesh.face_line[faces], face_group=mesh.face_group[faces],
                   face_material=mesh.face_material[faces], prim_face_start=None, notes=[])


def piece_scores(mesh: Mesh, faces: np.ndarray, n: int, settings: Settings, code: str) -> np.ndarray:
    """The worst value of rule ``code`` over the n x n pieces of each quad ``faces`` (Q,) int64.

    The pieces are built as the fix builds them (:func:`affinity.fix.apply.build`, the quads alone,
    each refined at ``n``) and measured by the rule itself (:func:`affinity.lint.quad_scores`), each
    in its quad's material (so texels have the size of the texture the quad binds).

    Returns
    -------
    (Q,) float64, 0 where no piece can be measured.
    """
    from ..lint import quad_scores
    from .apply import build
    from .layout import layout

    worst = np.zeros(len(faces))
    for first in range(0, len(faces), SCORE_BATCH):
        chosen = faces[first : first + SCORE_BATCH]
        alone = quads_alone(mesh, chosen)
        every = np.arange(len(chosen))
        refined = build(alone, layout(alone, every, np.full(len(chosen), n)))
        scores = quad_scores(refined.mesh, settings, code)
        values = np.zeros(len(chosen))
        np.maximum.at(values, refined.source[scores.faces], scores.values)
        worst[first : first + SCORE_BATCH] = values
    return worst


def needed_levels(mesh: Mesh, faces: np.ndarray, values: np.ndarray, code: str, fix: FixSettings) -> np.ndarray:
    """The smallest odd level n in [3, cap] at which no piece of each quad is flagged by ``code``.

    faces, values : (Q,) the flagged quads and their values. Returns (Q,) int64, ``cap + 2`` where even the
    cap is not enough.
    """
    from ..rules import RULES

    threshold = fix.lint.threshold(code)
    cap = fix.cap
    need = np.full(len(faces), cap + 2, dtype=np.int64)
    if cap < 3:
        return need
    ratio = np.divide(values, threshold, out=np.full(len(values), 4.0), where=threshold > 0)
    trial = np.clip(np.ceil(np.sqrt(np.maximum(ratio, 0))) - 1, 3, cap).astype(np.int64) | 1
    todo = np.ones(len(faces), dtype=bool)
    for n in range(int(trial.min(initial=cap)), cap + 1, 2):
        rows = np.flatnonzero(todo & (trial <= n))
        if len(rows) == 0:
            continue
        met = ~RULES[code].flagged(piece_scores(mesh, faces[rows], n, fix.lint, code), threshold)
        need[rows[met]] = n
        todo[rows[met]] = False
    return need


@dataclass(eq=False)
class Candidates:
    """The flagged quads of a mesh and what the first look decided for each (no refinement built yet).

    Attributes
    ----------
    faces : (K,) int64 ascending; reasons : (K,) object "" for a quad to refine, else why it is left
    need : (K,) int64 the level each needs; badness : (K,) float64 its worst value over its threshold
    uncut : (u,) int64 quads not flagged that a cut would fold (:func:`uncut_by_rule`)
    scored : the findings (:func:`flagged_quads`)
    """

    faces: np.ndarray
    reasons: np.ndarray
    need: np.ndarray
    badness: np.ndarray
    uncut: np.ndarray
    scored: dict


def candidates(mesh: Mesh, fix: FixSettings) -> Candidates:
    """Lint ``mesh``, pick the flagged quads, why each is left or the level it needs (module docstring)."""
    scored, leaving = flagged_quads(mesh, fix)
    found = np.unique(np.concatenate([faces for faces, _ in scored.values()] or [np.zeros(0, np.int64)]))
    twins = twin_faces(mesh)  # USD: prims of one authored mesh get one refinement, written once
    if twins is not None:
        found = np.flatnonzero(np.isin(twins, twins[found]))
    if fix.faces is not None:
        found = np.intersect1d(found, np.asarray(fix.faces, dtype=np.int64))
    reasons = np.full(len(found), "", dtype=object)
    for code, reason in reversed(left_by_rule().items()):  # the first rule in the table wins
        if not (reason == "nonplanar" and fix.refine_nonplanar):
            reasons[np.isin(found, leaving.get(code, []))] = reason
    reasons[(reasons == "degenerate") & pole_quads(mesh, found)] = ""
    if fix.subdivided:
        reasons[:] = "subdivided"
    need = np.zeros(len(found), dtype=np.int64)
    badness = np.zeros(len(found))
    at = {}
    for code, (faces, values) in scored.items():
        rows = np.searchsorted(found, faces)
        keep = (rows < len(found)) & (found[np.minimum(rows, len(found) - 1)] == faces)
        threshold = fix.lint.threshold(code)
        ratio = values[keep] / threshold if threshold else values[keep]
        badness[rows[keep]] = np.maximum(badness[rows[keep]], ratio)
        at[code] = rows, keep
    from .budget import beyond_budget

    reasons[beyond_budget(mesh, badness, reasons, fix)] = "over-budget"  # not searched: far past the budget
    for code, (faces, values) in scored.items():
        rows, keep = at[code]
        keep[keep] &= reasons[rows[keep]] == ""
        need[rows[keep]] = np.maximum(need[rows[keep]], needed_levels(mesh, faces[keep], values[keep], code, fix))
    if twins is not None:
        need, reasons = alike_across_twins(twins[found], need, reasons)
    reasons[(reasons == "") & (need > fix.cap)] = "over-cap"
    uncut = np.unique(np.concatenate([leaving.get(code, np.zeros(0, np.int64)) for code in uncut_by_rule()]))
    uncut = uncut[mesh.face_sizes[uncut] == 4]
    uncut = uncut[~pole_quads(mesh, uncut)]
    return Candidates(found, reasons, need, badness, np.setdiff1d(uncut, found), scored)


def readings(mesh: Mesh, faces: np.ndarray, n: np.ndarray, scored: dict, fix: FixSettings) -> tuple:
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
