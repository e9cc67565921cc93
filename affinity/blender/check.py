"""Lint a Blender object in memory: findings as JSON-like dicts, and a per-face error.

``affinity.lint`` and ``affinity.settings`` are imported when a check runs, not
when this module is imported (the lint core is being restructured; these two
import paths stay).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .convert import Conversion, convert_object
from .modifiers import SubdivisionModifier, subdivision_modifier

_CONVERSION_OPTIONS = ("evaluated", "uv_layer")


@dataclass(eq=False)
class ObjectCheck:
    """The outcome of linting one object.

    ``hits`` are the lint's :class:`~affinity.findings.RuleHits` (faces numbered
    like the converted mesh's polygons); ``findings`` the same as dicts with the
    keys of a JSON finding plus ``unit`` and ``level`` (and ``original_face`` for
    an evaluated mesh); ``notes`` say what was skipped and why, and what the object's
    Subdivision Surface modifier draws (``subdivision``, None without one).
    """

    conversion: Conversion
    settings: object
    hits: list
    findings: list[dict]
    notes: list[str] = field(default_factory=list)
    subdivision: SubdivisionModifier | None = None


def findings(obj, **settings) -> list[dict]:
    """Lint the mesh of ``obj`` and return every finding as a dict.

    Keyword arguments are the fields of :class:`affinity.settings.Settings`
    (``select``, ``ignore``, ``thresholds``, ``measure``, ``diagonal``,
    ``texture_size``) plus ``evaluated`` and ``uv_layer`` of
    :func:`~affinity.blender.convert.mesh_from_object`. Each dict has the keys
    of a finding in ``affinity check --format json`` (``path`` is the object's
    name, ``line`` and ``column`` are 0, ``face`` the polygon index) and
    ``unit`` and ``level``.
    """
    return check_object(obj, **settings).findings


def check_object(obj, **options) -> ObjectCheck:
    """:func:`findings` with the conversion, the raw hits and the notes for the panel.

    Textures are Blender's images that the materials read (:mod:`.texturemaps`), held in memory
    while the lint runs: each quad's texel unit is its material's image size (a UDIM tile's own), as
    ``affinity check`` reads a file's header, else ``texture_size``; Q101 is read through them (C).
    """
    from ..lint import mesh_report
    from ..rules import RULES, resolve_codes
    from ..settings import Settings
    from ..textures.held import holding

    convert = {k: options.pop(k) for k in _CONVERSION_OPTIONS if k in options}
    conversion = convert_object(obj, **convert)
    mesh = conversion.mesh
    notes = list(conversion.notes)
    if conversion.uv_layer is None:
        notes.extend(f"{code} skipped: the mesh has no UV map"
                     for code in resolve_codes(options.get("select"), options.get("ignore"))
                     if RULES[code].scored and RULES[code].attribute == "texcoords")
    settings = Settings(**options)
    with holding(conversion.textures.held):
        report = mesh_report(mesh.path, mesh, settings)  # check's own path from a mesh to its findings
    rows = _finding_dicts(report, settings, conversion.original_face if convert.get("evaluated") else None)
    subdivision = subdivision_modifier(obj)
    if subdivision is not None:
        notes.append(subdivision.note(bool(convert.get("evaluated"))))
    return ObjectCheck(conversion, settings, report.hits, rows, notes, subdivision)


def _finding_dicts(report, settings, original_face) -> list[dict]:
    from ..output import file_findings, finding_dict

    rows = []
    for finding in file_findings(report)[0]:
        row = finding_dict(finding)
        measure = settings.measure_of(finding.code)
        if measure is not None:  # as in affinity check --format json
            row["measure"] = measure
        if original_face is not None:
            row["original_face"] = int(original_face[finding.face]) if finding.face >= 0 else -1
        rows.append(row)
    return rows


def severity(hits) -> np.ndarray:
    """(n,) float64: how many times over (or under) its limit each finding of one rule is.

    A flagged value v against a positive threshold t reads max(v / t, t / v):
    2.0 is twice the limit for the rules that flag above it, half the limit
    for those that flag at or below it (Q201, Q301), without this module having
    to know which is which. Findings without a threshold, or with a value that
    is not positive, read 1.0. Where Q101's visible reading read C, the limit is
    ``visible-warning`` (the finding's ``threshold`` in the JSON) and C reads C / t:
    a quad the shift flags but whose crease shows nothing (C = 0) reads 0. The worst
    finding of a rule is the most severe.

    Each value is read against its own threshold (:meth:`~affinity.findings.RuleHits.thresholds`: C against
    visible-warning where Q101 read it through a texture, the shift against the texel threshold elsewhere).

    Parameters
    ----------
    hits : settled RuleHits with ``values`` (n,) float64 and ``visible`` None or VisibleColumns
    """
    v, t = hits.values, hits.thresholds()
    ratio = np.ones(len(v))
    positive = (v > 0) & (t > 0)
    ratio[positive] = np.maximum(v[positive] / t[positive], t[positive] / v[positive])
    if hits.visible is not None:
        read = hits.visible.read()
        ratio[read] = v[read] / t[read]
    return ratio


def face_error(hits, face_map: np.ndarray, n_faces: int) -> np.ndarray:
    """(n_faces,) float32 per-face error: the :func:`severity` of the face's worst finding, 0 if none.

    Parameters
    ----------
    hits : list of RuleHits, faces numbered like the converted mesh
    face_map : (F,) int64, the face of the ``n_faces`` target mesh each converted face
        maps to (-1: none), e.g. :attr:`Conversion.original_face`
    """
    error = np.zeros(n_faces, dtype=np.float64)
    for h in hits:
        on_face = h.faces >= 0  # Q205 is about the whole mesh: face -1
        target = face_map[h.faces[on_face]]
        mapped = target >= 0
        np.maximum.at(error, target[mapped], severity(h)[on_face][mapped])
    return error.astype(np.float32)
