"""Places: neighbouring flagged faces of one rule, grouped, ranked, and chosen for close-ups.

A place is a connected set of faces flagged by the same rule, faces being
neighbours when they share a vertex. Places are ranked by the rule's level, then
by how far their worst face is beyond the threshold, and chosen taking turns
between rules, so every flagged rule gets a close-up before any rule gets a
second one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..findings import RuleHits
from ..mesh import Mesh
from ..rules import RULES

LEVEL_ORDER = {"error": 0, "warning": 1, "info": 2}


@dataclass(frozen=True)
class Place:
    """Neighbouring faces flagged by one rule.

    code : the rule
    faces : (P,) int64, the place's faces in file order
    values : (P,) float64, their values in the rule's unit
    worst : the face with the worst value (the one the close-up is named by)
    value : its value
    beyond : how far beyond the threshold it is, as a ratio >= 1 (inf at a zero value of a lowest-is-worst rule)
    """

    code: str
    faces: np.ndarray
    values: np.ndarray
    worst: int
    value: float
    beyond: float

    @property
    def level(self) -> str:
        return RULES[self.code].level


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
    from ..draw.closeup import face_vertices

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


def places_of(mesh: Mesh, hits: RuleHits) -> list[Place]:
    """Every place of one rule's hits, worst first (quads with the rule's ``faces`` >= 0 only)."""
    rule = RULES[hits.code]
    keep = hits.faces >= 0
    faces, values = hits.faces[keep], hits.values[keep]
    order = np.argsort(faces)
    faces, values = faces[order], values[order]
    places = []
    for members in group_faces(mesh, faces):  # one pass per place, not per face
        group, vals = faces[members], values[members]
        k = int(np.argmin(vals) if rule.worst == "lowest" else np.argmax(vals))
        value = float(vals[k])
        with np.errstate(divide="ignore", invalid="ignore"):
            beyond = (hits.threshold / value if value > 0 else np.inf) if rule.worst == "lowest" else (
                value / hits.threshold if hits.threshold > 0 else np.inf)
        places.append(Place(hits.code, group, vals, int(group[k]), value, float(beyond)))
    places.sort(key=lambda p: (-p.beyond, p.worst))
    return places


def choose_places(by_rule: dict[str, list[Place]], limit: int) -> list[Place]:
    """Up to ``limit`` places, taking turns between rules.

    Rules go in order of level (errors first), then of their worst place; round
    ``k`` takes each rule's ``k``-th place, so each flagged rule has a close-up
    when ``limit`` is at least the number of rules.
    """
    rules = sorted((code for code in by_rule if by_rule[code]),
                   key=lambda code: (LEVEL_ORDER[RULES[code].level], -by_rule[code][0].beyond, code))
    chosen: list[Place] = []
    rounds = max((len(by_rule[code]) for code in rules), default=0)
    for k in range(rounds):
        for code in rules:
            if len(chosen) == limit:
                return chosen
            if k < len(by_rule[code]):
                chosen.append(by_rule[code][k])
    return chosen
