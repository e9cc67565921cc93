"""The fix's output budget: at most ``max_faces_added`` new faces and about ``max_bytes_added`` new bytes.

A fix that would exceed it refines the worst quads first (by value over threshold) up to the
budget and leaves the rest ``over-budget``. The faces a plan adds are counted exactly from the
cuts (:mod:`affinity.fix.patterns`) before anything is built; the bytes are an estimate per new
face (its face line and about one new vertex with its uv and normal).
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh

#: Bytes of one number written in its shortest round-trip form, about (``%r`` of a float64), and a space.
NUMBER_BYTES = 20


def estimated_bytes(mesh: Mesh, faces_added: int) -> int:
    """The bytes an OBJ grows by with ``faces_added`` new faces: per face an ``f`` line of four corners and
    about one new ``v`` (with ``vt`` and ``vn`` where the mesh has them)."""
    tables = 1 + (mesh.corner_texcoord is not None) + (mesh.corner_normal is not None)
    digits = len(str(len(mesh.positions) + max(faces_added, 0))) + 1
    face_line = 2 + 4 * digits * tables
    vertex_lines = NUMBER_BYTES * (3 + 2 * (mesh.corner_texcoord is not None) + 3 * (mesh.corner_normal is not None))
    return int(max(faces_added, 0) * (face_line + vertex_lines + 3 * tables))


def counted_faces_added(mesh: Mesh, refine_faces: np.ndarray, refine_n: np.ndarray, frozen: np.ndarray) -> int:
    """The faces the refinement adds, counted from its cuts without building it."""
    from .layout import face_patterns, layout
    from .patterns import face_pattern

    placed = layout(mesh, refine_faces, refine_n, frozen)
    replaced = np.union1d(refine_faces, placed.transition_faces)
    return sum((len(face_pattern(*pattern).polygons) - 1) * len(faces)
               for pattern, faces in face_patterns(mesh, placed, replaced))


def face_limit(mesh: Mesh, fix) -> int:
    """The most faces the budget of ``fix`` lets the fix add to ``mesh`` (faces, and bytes per face)."""
    per_face = estimated_bytes(mesh, fix.max_faces_added) / max(fix.max_faces_added, 1)
    return min(fix.max_faces_added, int(fix.max_bytes_added // max(per_face, 1)))


def beyond_budget(mesh: Mesh, badness: np.ndarray, reasons: np.ndarray, fix) -> np.ndarray:
    """(k,) int64 rows of the quads to refine (``reasons`` "") that are far past the budget, the least bad
    first: those whose pieces alone, at the level the 1/n^2 law guesses from ``badness`` (value over
    threshold), pass twice the budget counting from the worst. Their levels need not be searched."""
    rows = np.flatnonzero(reasons == "")
    order = rows[np.argsort(-badness[rows], kind="stable")]
    guess = np.clip(np.ceil(np.sqrt(badness[order])), 3, fix.cap).astype(np.int64) | 1
    return order[np.cumsum(guess * guess - 1) > 2 * face_limit(mesh, fix)]


def within_budget(mesh: Mesh, found, reasons: np.ndarray, fix) -> None:
    """Leave ``over-budget`` (in ``reasons`` (K,), in place) the least bad quads to refine that do not fit the
    budget of ``fix`` (:class:`affinity.fix.plan.FixSettings`); ``found`` the plan's candidates."""
    rows = np.flatnonzero(reasons == "")
    if len(rows) == 0:
        return
    limit = face_limit(mesh, fix)
    order = rows[np.argsort(-found.badness[rows], kind="stable")]
    keep = len(order)
    frozen = np.union1d(found.faces[reasons != ""], found.uncut)
    while True:
        kept = np.sort(order[:keep])
        dropped = order[keep:]
        added = counted_faces_added(mesh, found.faces[kept], found.need[kept], np.union1d(frozen, found.faces[dropped]))
        if added <= limit or keep == 0:
            break
        keep = int(keep * limit / added * 0.95)  # faces grow about as the quads refined
    reasons[order[keep:]] = "over-budget"
