"""Lint results, kept as arrays per rule so a million findings cost no Python objects."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


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
    """

    code: str
    faces: np.ndarray
    lines: np.ndarray
    values: np.ndarray
    threshold: float
    groups: np.ndarray

    def __len__(self) -> int:
        return len(self.faces)


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
    are the loader's remarks on what it did not check.
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

    @property
    def n_findings(self) -> int:
        return sum(len(h) for h in self.hits)
