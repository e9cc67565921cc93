"""Faces that must be fixed alike: the prims of a USD stage that compose one authored mesh (same layer,
same prim path, :attr:`affinity.mesh.Mesh.prim_sources`) get one refinement, so that the fix writes
their geometry once (:mod:`affinity.fix.usdlayer`). Pure NumPy: no ``pxr``."""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh


def twin_faces(mesh: Mesh) -> np.ndarray | None:
    """(F,) int64: for each face, the same face of the first prim that shares its prim's authored geometry (its
    own index where it shares none); None when no two prims share (every other format, most stages).

    >>> from affinity.mesh import Mesh
    >>> m = Mesh(path="s.usda", positions=np.zeros((3, 3)), face_start=np.arange(0, 10, 3),
    ...          corner_vertex=np.array([0, 1, 2] * 3), face_line=np.zeros(3, dtype=np.int64),
    ...          prim_face_start=np.array([0, 1, 2, 3]), group_names=["/X/A", "/B", "/Y/A"],
    ...          prim_sources=[("g.usd", "/A"), ("o.usd", "/B"), ("g.usd", "/A")])
    >>> twin_faces(m).tolist()
    [0, 1, 0]
    """
    sources, starts = mesh.prim_sources, mesh.prim_face_start
    if not sources or starts is None or len(sources) < 2:
        return None
    sizes = np.diff(starts)
    first: dict = {}
    owner = np.array([first.setdefault((source, int(n)), p) if source is not None else p
                      for p, (source, n) in enumerate(zip(sources, sizes))])
    if (owner == np.arange(len(owner))).all():
        return None
    prim = np.repeat(np.arange(len(sizes)), sizes)
    return np.arange(starts[-1]) - starts[prim] + starts[owner][prim]


def alike_across_twins(twins: np.ndarray, need: np.ndarray, reasons: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per candidate face (twins (C,) int64 its twin), the largest ``need`` (C,) int64 over its twins and the
    first left reason (C,) object of any of them ("" where none leaves it): twins are refined alike or left
    alike."""
    order = np.unique(twins, return_inverse=True)[1].reshape(-1)
    most = np.zeros(order.max(initial=-1) + 1, dtype=need.dtype)
    np.maximum.at(most, order, need)
    left = np.full(len(most), "", dtype=object)
    rows = np.flatnonzero(reasons != "")[::-1]  # assigned last to first: the first candidate's reason wins
    left[order[rows]] = reasons[rows]
    return most[order], left[order]


def readings_from_twins(twins: np.ndarray, *readings: np.ndarray) -> tuple[np.ndarray, ...]:
    """The refined faces' readings (codes first, then before, after, units: (R,) each), a face refined only for
    its twins' sake (code "") given the reading of a twin that has one."""
    read = readings[0] != ""
    if read.all() or not read.any():
        return readings
    reader = np.full(twins.max() + 1, -1, dtype=np.int64)
    reader[twins[read]] = np.flatnonzero(read)
    rows = np.where(read, np.arange(len(twins)), reader[twins])
    rows = np.where(rows >= 0, rows, np.arange(len(twins)))
    return tuple(reading[rows] for reading in readings)
