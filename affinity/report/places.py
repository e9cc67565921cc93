"""Places: neighbouring flagged faces of one rule, grouped, ranked, and chosen for close-ups.

A place is a connected set of faces flagged by the same rule, faces being
neighbours when they share a vertex. Places are chosen level by level (errors,
then warnings, then info: the close-ups show first what fails the gate), and
within a level taking turns between rules, each rule's worst first, so every
rule with errors gets a close-up before any rule gets a second one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..findings import RuleHits
from ..mesh import Mesh
from ..rules import RULES
from . import PLACE_FACES

LEVEL_ORDER = {"error": 0, "warning": 1, "info": 2}
#: A bigger group is carved into this many places around its successive worst faces (the ones a close-up
#: may show); the rest of it is cut into shells of ``PLACE_FACES`` by distance, so every place stays small.
CARVED = 6
#: Two places are mirror twins when their worst faces' centroids are mirror images across a bounding-box
#: mid-plane within ``TWIN_DISTANCE`` of its diagonal and their worst values agree to ``TWIN_VALUE`` (relative):
#: positions of a symmetric model mirror exactly, its uv atlas does not (Spot's halves: 1.030 and 0.996 texels).
TWIN_VALUE = 0.1
TWIN_DISTANCE = 1e-3


@dataclass(frozen=True)
class Place:
    """Neighbouring faces flagged by one rule.

    code : the rule
    faces : (P,) int64, the place's faces in file order
    values : (P,) float64, their values in the rule's unit
    worst : the face with the worst value (the one the close-up is named by)
    value : its value
    beyond : how far beyond the threshold it is, as a ratio >= 1 (inf at a zero value of a lowest-is-worst rule)
    level : the level of the worst face's finding (``error`` above the rule's visibility threshold)
    group : the group of neighbours it was carved from (numbered per rule; -1: a place of its own)
    shift : where ``value`` is C (Q101 read through a texture), the worst face's shift in texels beside it; else NaN
    """

    code: str
    faces: np.ndarray
    values: np.ndarray
    worst: int
    value: float
    beyond: float
    level: str
    group: int = -1
    shift: float = float("nan")


def read_shifts(hits: RuleHits) -> np.ndarray:
    """(n,) float64: each finding's shift in texels where its value is C (the visible reading), else NaN."""
    columns = hits.visible
    if columns is None:
        return np.full(len(hits.faces), np.nan)
    return np.where(columns.read(), columns.shifts, np.nan)


def connected_components(n_items: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Label the connected components of a graph of ``n_items`` nodes with edges (a[k], b[k]).

    Vectorized label propagation with pointer jumping: every node takes the
    smallest label among its edges' ends, then each label jumps to its label's
    label, until nothing changes (a few dozen rounds for mesh patches).

    Returns
    -------
    (n_items,) int64, the smallest node index of each node's component.
    """
    label = np.arange(n_items)
    while True:
        smallest = np.minimum(label[a], label[b])
        new = label.copy()
        np.minimum.at(new, a, smallest)
        np.minimum.at(new, b, smallest)
        new = new[new]
        if np.array_equal(new, label):
            return label
        label = new


def group_faces(mesh: Mesh, faces: np.ndarray) -> list[np.ndarray]:
    """Split ``faces`` (n,) int64, sorted and unique, into groups of neighbours (sharing a vertex).

    Returns one (k,) int64 array of positions into ``faces`` per group, in the
    order of the groups' first face.
    """
    from ..draw import face_vertices

    if len(faces) == 0:
        return []
    vertices, owner = face_vertices(mesh, faces)
    item = np.searchsorted(faces, owner)
    # Join every face at a vertex to the first face at that vertex: a star per vertex connects them all.
    order = np.argsort(vertices, kind="stable")
    vertices, item = vertices[order], item[order]
    first = np.r_[True, vertices[1:] != vertices[:-1]]
    leader = item[np.flatnonzero(first)[np.cumsum(first) - 1]]
    label = connected_components(len(faces), item, leader)
    _, inverse = np.unique(label, return_inverse=True)
    order = np.argsort(inverse, kind="stable")
    return np.split(order, np.flatnonzero(np.diff(inverse[order])) + 1)


def carve(values: np.ndarray, centroids: np.ndarray, lowest: bool, limit: int = PLACE_FACES,
          carved: int = CARVED) -> list[np.ndarray]:
    """Cut one group of ``values`` (n,) and face ``centroids`` (n, 3) into parts of at most ``limit`` items.

    Up to ``carved`` parts are the ``limit`` items nearest (by centroid) the worst item left; the rest
    is cut into shells of ``limit`` by distance from the last worst one. Returns (k,) int64 positions per
    part. A group of ``limit`` or fewer items stays whole.
    """
    left = np.arange(len(values))
    parts = []
    while len(left) > limit and len(parts) < carved:
        worst = left[np.argmin(values[left]) if lowest else np.argmax(values[left])]
        order = np.argsort(np.linalg.norm(centroids[left] - centroids[worst], axis=1), kind="stable")
        parts.append(np.sort(left[order[:limit]]))
        left = np.sort(left[order[limit:]])
    if len(left) > limit:
        order = left[np.argsort(np.linalg.norm(centroids[left] - centroids[parts[-1][0]], axis=1), kind="stable")]
        parts.extend(np.sort(shell) for shell in np.array_split(order, -(-len(order) // limit)))
    elif len(left):
        parts.append(left)
    return parts


def repeats(place: Place, earlier: Place, centroids: np.ndarray, low: np.ndarray, high: np.ndarray) -> bool:
    """Whether ``place`` shows ``earlier``'s defect again: the same rule, worst values within ``TWIN_VALUE``,
    and either another part of the same group (a ring of equal faces around a vase, a pole's fan) or its mirror
    twin (its worst face's centroid the mirror image of ``earlier``'s across a mid-plane of the bounding box
    ``low``/``high`` (3,), within ``TWIN_DISTANCE`` of its diagonal). ``centroids`` (F, 3) of the mesh's faces.

    A symmetric model (a face, a car, a cow) flags its two halves alike, and a carved group its parts alike: a
    second close-up of either shows nothing new.
    """
    if place.code != earlier.code or abs(place.value - earlier.value) > TWIN_VALUE * abs(earlier.value):
        return False
    if place.group >= 0 and place.group == earlier.group:
        return True
    tolerance = TWIN_DISTANCE * max(float(np.linalg.norm(high - low)), 1e-300)
    at, there = centroids[place.worst], centroids[earlier.worst]
    mirrored = np.where(np.eye(3, dtype=bool), low + high - there, there)  # row k: mirrored across plane k
    off_plane = np.abs(there - (low + high) / 2) > tolerance
    return bool((off_plane & (np.linalg.norm(mirrored - at, axis=1) <= tolerance)).any())


def places_of(mesh: Mesh, hits: RuleHits, limit: int = PLACE_FACES) -> list[Place]:
    """Every place of one rule's hits, worst first (quads with ``faces`` >= 0 only).

    A group of neighbours bigger than ``limit`` faces is :func:`carve`d into places of at most ``limit``.
    """
    from ..draw import face_centroids

    rule = RULES[hits.code]
    keep = hits.faces >= 0
    # Worst by each value against its own threshold (worst_key): C and the shift are not one unit.
    faces, values, levels = hits.faces[keep], hits.values[keep], hits.levels()[keep]
    key, shifts = hits.worst_key()[keep], read_shifts(hits)[keep]
    order = np.argsort(faces)
    faces, values, levels, key, shifts = faces[order], values[order], levels[order], key[order], shifts[order]
    centroids = face_centroids(mesh)
    places = []
    groups = group_faces(mesh, faces)
    parts = [(number, members[part]) for number, members in enumerate(groups)  # one pass per place, not per face
             for part in carve(key[members], centroids[faces[members]], True, limit)]
    for number, members in parts:
        group, vals = faces[members], values[members]
        k = int(np.argmin(key[members]))
        value = float(vals[k])
        with np.errstate(divide="ignore", invalid="ignore"):
            beyond = (hits.threshold / value if value > 0 else np.inf) if rule.worst == "lowest" else (
                -key[members][k] if hits.ranked_by_ratio else np.inf)
        places.append(Place(hits.code, group, vals, int(group[k]), value, float(beyond), str(levels[members][k]),
                            number, float(shifts[members][k])))
    places.sort(key=lambda p: (-p.beyond, p.worst))
    return places


def choose_places(by_rule: dict[str, list[Place]], limit: int) -> list[Place]:
    """Up to ``limit`` places: every error place before any warning place, every warning before any info.

    Within a level the rules take turns: they go in order of how far their worst place of that level is beyond
    the threshold, and round ``k`` takes each rule's ``k``-th place of the level, so each rule with errors has a
    close-up before any rule gets a second one.
    """
    chosen: list[Place] = []
    for level in sorted(LEVEL_ORDER, key=LEVEL_ORDER.get):
        of_level = {code: [p for p in places if p.level == level] for code, places in by_rule.items()}
        rules = sorted((code for code in of_level if of_level[code]),
                       key=lambda code: (-of_level[code][0].beyond, code))
        rounds = max((len(of_level[code]) for code in rules), default=0)
        chosen += [of_level[code][k] for k in range(rounds) for code in rules if k < len(of_level[code])]
    return chosen[:limit]
