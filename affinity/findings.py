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


def report_to_bytes(report: FileReport) -> bytes:
    """``report`` as a self-contained ``.npz`` blob: arrays stored as they are, the rest as JSON.

    :func:`report_from_bytes` gives back an equal report (same dtypes, same
    values bit for bit), without pickle, so a damaged blob can only fail to load.
    """
    import io
    import json
    from dataclasses import fields

    arrays: dict[str, np.ndarray] = {}
    meta = {f.name: getattr(report, f.name) for f in fields(report) if f.name not in ("hits", "prim_face_start")}
    meta["hits"] = [{"code": h.code, "threshold": h.threshold} for h in report.hits]
    for k, hits in enumerate(report.hits):
        for name in _HIT_ARRAYS:
            arrays[f"hits{k}_{name}"] = getattr(hits, name)
    if report.prim_face_start is not None:
        arrays["prim_face_start"] = report.prim_face_start
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode("utf-8"), dtype=np.uint8)
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    return buffer.getvalue()


def report_from_bytes(data: bytes) -> FileReport:
    """The report :func:`report_to_bytes` stored; a damaged blob raises ValueError."""
    import io
    import json
    import zipfile
    import zlib

    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as blob:
            meta = json.loads(blob["meta"].tobytes().decode("utf-8"))
            hits = [
                RuleHits(h["code"], threshold=h["threshold"], **{name: blob[f"hits{k}_{name}"] for name in _HIT_ARRAYS})
                for k, h in enumerate(meta.pop("hits"))
            ]
            prim_face_start = blob["prim_face_start"] if "prim_face_start" in blob.files else None
            return FileReport(**meta, hits=hits, prim_face_start=prim_face_start)
    except (zipfile.BadZipFile, zlib.error, EOFError, KeyError, TypeError, OSError) as err:
        raise ValueError(f"not a stored report: {type(err).__name__}: {err}") from None


_HIT_ARRAYS = ("faces", "lines", "values", "groups")
