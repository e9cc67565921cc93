"""Q101-Q103 on the surface a renderer draws (design.md, "Subdivision"): the mesh refined to the level of the
``subdivision`` setting and ``profile`` (:meth:`affinity.settings.Settings.subdivision_level`), the scored
rules measured on the refined faces with the run's own settings (texture sizes, the visible reading,
diagonals), and each finding reported on its base face: the worst refined face's value, the level, and how
many of the face's refined faces the rule flags. The other rules stay on the cage.

Not measured: faces drawn at the limit surface (no split is drawn there), Loop meshes above level 0, and
Q103 on a USD mesh drawn subdivided (renderers ignore authored normals on a subdivision surface,
UsdGeomMesh); each gets one note.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..findings import RefinedColumns, RuleHits, VisibleColumns
from ..mesh import Mesh
from ..rules import RULES, resolve_codes
from .pieces import drawn_levels, local_faces
from .refine import Scheme, refine_uniform

#: Words of the USD loader's note on prims that subdivide, which a measured subdivided surface replaces.
CAGE_NOTE = "the findings are for the cage"


@dataclass(frozen=True)
class Piece:
    """Faces refined together: ``faces`` (n,) int64 of the mesh, their ``scheme`` and ``level`` (> 0)."""

    faces: np.ndarray
    scheme: Scheme
    level: int


def lint_where_drawn(mesh: Mesh, settings, visible: bool, scores: bool, lint_pass) -> tuple | None:
    """The lint of ``mesh`` with Q101-Q103 measured where the renderer draws them, as the fields of an
    :class:`affinity.lint.MeshLint` (hits, scores, notes); None where every face is drawn as its cage (then
    ``lint_pass``, :func:`affinity.lint.lint_pass` given by its caller, lints as it always did)."""
    face_scheme, schemes, levels = drawn_levels(mesh, settings)
    if all(level == 0 for level in levels):
        return None
    enabled = resolve_codes(settings.select, settings.ignore)
    scored = [code for code in enabled if RULES[code].scored]
    usd = mesh.subdivision is not None
    level_of = np.array([0 if level == "limit" else level for level in levels], dtype=np.int64)
    refinable = np.array([level != "limit" and level > 0 and scheme.scheme != "loop"
                          for scheme, level in zip(schemes, levels)])
    drawn_on_cage = (level_of == 0) & np.array([level != "limit" for level in levels])
    cage_face = drawn_on_cage[face_scheme]
    cage_settings = settings
    if not cage_face.any():  # the scored rules are measured on no cage face: the cage pass leaves them out
        cage_settings = replace(settings, select=[c for c in enabled if c not in scored] or ["-"], ignore=None)
    cage = lint_pass(mesh, cage_settings, visible, scores, where_drawn=False)
    hits = {h.code: h for h in cage.hits}
    for code in scored:
        if code in hits:
            hits[code] = hits[code].subset(cage_face[hits[code].faces])
    pieces = [Piece(np.flatnonzero(face_scheme == s), schemes[s], int(level_of[s]))
              for s in np.flatnonzero(refinable)]
    refined_codes = [c for c in scored if not (usd and RULES[c].attribute == "normals")]
    if pieces and refined_codes:
        refined, base, level = refined_mesh(mesh, pieces)
        found = lint_pass(refined, replace(settings, select=refined_codes, ignore=None), visible, where_drawn=False)
        measured = np.bincount(base, minlength=mesh.n_faces)
        for h in found.hits:
            on_base = on_base_faces(mesh, h, base, level, measured)
            hits[h.code] = on_base if h.code not in hits else joined(hits[h.code], on_base)
    order = {code: i for i, code in enumerate(RULES)}
    kept = sorted((h for h in hits.values() if len(h)), key=lambda h: order[h.code])
    return kept, cage.scores, _notes(mesh, settings, schemes, levels, scored, face_scheme)


def refined_mesh(mesh: Mesh, pieces: list[Piece]) -> tuple[Mesh, np.ndarray, np.ndarray]:
    """The pieces refined (holes left out) as one mesh of quads carrying the base faces' lines, groups and
    materials; with (R,) int64 each refined face's base face and (R,) int64 its level."""
    parts = [_refined_piece(mesh, piece) for piece in pieces]
    base = np.concatenate([part["base"] for part in parts])
    vertex_offsets = np.cumsum([0] + [len(part["positions"]) for part in parts])
    channels = {}
    for name in ("texcoords", "normals"):
        channels[name] = _joined_channel([part.get(name) for part in parts], [len(part["base"]) for part in parts])
    colors = None
    if mesh.colors is not None:
        colors = np.concatenate([part["colors"] for part in parts])
    refined = Mesh(
        path=mesh.path,
        positions=np.concatenate([part["positions"] for part in parts]),
        face_start=4 * np.arange(len(base) + 1, dtype=np.int64),
        corner_vertex=np.concatenate([part["corner_vertex"] + offset
                                      for part, offset in zip(parts, vertex_offsets)]),
        face_line=mesh.face_line[base],
        texcoords=channels["texcoords"][0], corner_texcoord=channels["texcoords"][1],
        normals=channels["normals"][0], corner_normal=channels["normals"][1],
        colors=colors,
        group_names=mesh.group_names, face_group=mesh.face_group[base],
        material_names=mesh.material_names, face_material=mesh.face_material[base],
        material_textures=mesh.material_textures, material_maps=mesh.material_maps, resources=mesh.resources,
        up_axis=mesh.up_axis, meters_per_unit=mesh.meters_per_unit,
    )
    level = np.concatenate([np.full(len(part["base"]), piece.level) for part, piece in zip(parts, pieces)])
    return refined, base, level


def _refined_piece(mesh: Mesh, piece: Piece) -> dict:
    """One piece refined, in its own vertex numbering: positions, corner_vertex, base (global faces), colors,
    and the channels the piece has at every corner (texcoords, normals: (values, corner index))."""
    local = local_faces(mesh, piece.faces, piece.scheme)
    channels = {name: found for name, index_name in (("texcoords", "corner_texcoord"), ("normals", "corner_normal"))
                if (found := local.channel(getattr(mesh, name), getattr(mesh, index_name))) is not None}
    data = {} if mesh.colors is None else {"colors": mesh.colors[local.used]}
    refined = refine_uniform(local.face_start, local.corner_vertex, local.positions, piece.level, local.scheme,
                             channels, data)
    drawn = ~refined.hole
    kept_corners = np.repeat(drawn, 4)
    part = {"positions": refined.positions, "corner_vertex": refined.corner_vertex[kept_corners],
            "base": piece.faces[refined.base_face[drawn]]}
    if mesh.colors is not None:
        part["colors"] = refined.vertex_data["colors"]
    for name, (values, corner_value) in refined.channels.items():
        part[name] = (values, corner_value[kept_corners])
    return part


def _joined_channel(channels: list, faces: list[int]) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The pieces' (values, corner index) of one channel as one table and index; -1 at the corners of pieces
    without it; (None, None) when no piece has it."""
    present = [channel for channel in channels if channel is not None]
    if not present:
        return None, None
    offset, values, index = 0, [], []
    for channel, n in zip(channels, faces):
        if channel is None:
            index.append(np.full(4 * n, -1, dtype=np.int64))
            continue
        values.append(channel[0])
        index.append(channel[1] + offset)
        offset += len(channel[0])
    return np.concatenate(values), np.concatenate(index)


def on_base_faces(mesh: Mesh, hits: RuleHits, base: np.ndarray, level: np.ndarray, measured: np.ndarray) -> RuleHits:
    """A rule's findings on refined faces as findings on their base faces: each base face's worst refined
    face (its value, visible reading and remark), the level, and how many refined faces the rule flags;
    ``measured`` (F,) int64 counts each base face's refined faces."""
    faces = base[hits.faces]
    badness = hits.values if RULES[hits.code].worst == "lowest" else -hits.values
    order = np.lexsort((badness, faces))
    first = order[np.concatenate([[True], faces[order][1:] != faces[order][:-1]])]
    on = faces[first]
    flagged = np.bincount(faces, minlength=mesh.n_faces)[on]
    levels = level[hits.faces[first]]
    remarks = [f"at L{lv}, {k} of {n} refined faces flagged"
               for lv, k, n in zip(levels.tolist(), flagged.tolist(), measured[on].tolist())]
    if hits.details is not None:
        remarks = ["; ".join(filter(None, [remark, hits.details[row]])) for remark, row in zip(remarks, first.tolist())]
    return RuleHits(hits.code, on, mesh.face_line[on], hits.values[first], hits.threshold, mesh.face_group[on],
                    details=remarks, visible=None if hits.visible is None else hits.visible.subset(first),
                    refined=RefinedColumns(levels.astype(np.int8), flagged.astype(np.int32),
                                           measured[on].astype(np.int32)))


def joined(cage: RuleHits, refined: RuleHits) -> RuleHits:
    """One rule's findings on cage faces and on refined base faces as one record, in face order."""
    n = len(cage)
    refined_columns = RefinedColumns(np.zeros(n, np.int8), np.ones(n, np.int32), np.ones(n, np.int32))
    visible = None
    if cage.visible is not None or refined.visible is not None:
        visible = _joined_visible(cage.visible, refined.visible, n, len(refined))
    both = RuleHits(cage.code, np.concatenate([cage.faces, refined.faces]),
                    np.concatenate([cage.lines, refined.lines]), np.concatenate([cage.values, refined.values]),
                    cage.threshold, np.concatenate([cage.groups, refined.groups]),
                    details=(cage.details or [None] * n) + (refined.details or [None] * len(refined)),
                    visible=visible,
                    refined=RefinedColumns(*(np.concatenate([getattr(refined_columns, name),
                                                             getattr(refined.refined, name)])
                                             for name in RefinedColumns.ARRAYS)))
    return both.subset(np.argsort(both.faces, kind="stable"))


def _joined_visible(a: VisibleColumns | None, b: VisibleColumns | None, n_a: int, n_b: int) -> VisibleColumns:
    """Two visible readings (None: nothing read on those findings) as one, texture lists joined."""
    def unread(n):
        return VisibleColumns(np.full(n, np.nan), np.full(n, np.nan), np.zeros(n, np.int8), np.full(n, -1, np.int32),
                              [], [], [], (b or a).limits, (b or a).fixed)

    a, b = a or unread(n_a), b or unread(n_b)
    picks = np.concatenate([a.picks, np.where(b.picks >= 0, b.picks + len(a.textures), -1)]).astype(np.int32)
    return VisibleColumns(np.concatenate([a.values, b.values]), np.concatenate([a.shifts, b.shifts]),
                          np.concatenate([a.bounds, b.bounds]), picks, a.textures + b.textures, a.roles + b.roles,
                          a.units + b.units, a.limits, a.fixed)


def _notes(mesh: Mesh, settings, schemes: list[Scheme], levels: list, scored: list[str],
           face_scheme: np.ndarray) -> list[str]:
    """The mesh's notes, the USD loader's "findings are for the cage" replaced by what was measured where."""
    notes = [note for note in mesh.notes if CAGE_NOTE not in note]
    why = (f"--subdivision {settings.subdivision}" if settings.subdivision != "auto"
           else f"profile {settings.profile}")
    refined = sorted({level for scheme, level in zip(schemes, levels)
                      if level != "limit" and level > 0 and scheme.scheme != "loop"})
    if refined and scored:
        notes.append(f"{', '.join(scored)} measured on the surface refined to level "
                     f"{' and '.join(map(str, refined))} ({why}), each finding on its base face")
    if "limit" in levels and scored:
        notes.append(f"{', '.join(scored)} not reported where the limit surface is drawn ({why}): no split, "
                     "no crease")
    loops = sum(scheme.scheme == "loop" and level != 0 for scheme, level in zip(schemes, levels))
    if loops and scored:
        notes.append(f"{loops} mesh prim{'s' * (loops != 1)} subdivide{'s' * (loops == 1)} with Loop: "
                     f"{', '.join(scored)} not measured above level 0")
    normals = [code for code in scored if RULES[code].attribute == "normals"]
    if mesh.subdivision is not None and normals and mesh.corner_normal is not None:
        has_normals = np.bincount(face_scheme[np.repeat(np.arange(mesh.n_faces), mesh.face_sizes)],
                                  mesh.corner_normal >= 0, minlength=len(schemes)) > 0
        for s, level in enumerate(levels):
            if level != 0 and has_normals[s]:
                notes.append(f"{mesh.group_names[s]}: {normals[0]} not measured: renderers ignore authored "
                             "normals on a mesh that subdivides (UsdGeomMesh)")
    return notes
