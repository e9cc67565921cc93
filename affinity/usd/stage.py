"""Check an open ``Usd.Stage`` as ``affinity check`` checks its file, for the validators.

The stage is read in memory (what the host application shows, saved or not) by the
USD loader, linted with the settings that govern its root layer's file (the
defaults for a stage that has none), and a mesh that several prims reference from
one geometry layer is reported once, at the first of them
(:func:`affinity.findings.share_authored_geometry`). A prim that cannot be read (a
malformed mesh, a reference or payload that cannot be opened) is kept aside with its
reason instead of failing the stage.

Each validator runs once per mesh prim, and several validators run on one stage:
the check is made once per stage and time and kept until the stage changes
(``Usd.Notice.ObjectsChanged``).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

from ..output import Finding

#: Stages whose check is kept, at most: a host validating one stage after another frees the old ones.
KEPT_STAGES = 8


@dataclass(eq=False)
class StageCheck:
    """The outcome of checking one stage.

    Attributes
    ----------
    path : the root layer's file, or its identifier for a stage in memory
    findings : reporting prim path -> its findings (file-level ones at the prim they concern)
    reported_at : mesh prim path -> the prim its findings are reported at (itself, or the first
        prim referencing the same geometry layer)
    bad_prims : prim path -> why it cannot be read
    error : why the stage cannot be read at all, else None
    notes : the loader's notes (hidden prims, subdivision surfaces, ...)
    """

    path: str
    findings: dict[str, list[Finding]] = field(default_factory=dict)
    reported_at: dict[str, str] = field(default_factory=dict)
    bad_prims: dict[str, str] = field(default_factory=dict)
    error: str | None = None
    notes: list[str] = field(default_factory=list)


def check_stage(stage, time: float | None = None) -> StageCheck:
    """Lint every drawn mesh prim of ``stage`` (at ``time``; None: the earliest sample, as ``affinity check``)."""
    from ..config import file_settings
    from ..errors import MeshError, SkippedFile
    from ..lint import mesh_report
    from ..loaders.usd import UsdOptions, load_stage
    from ..output import file_findings

    layer = stage.GetRootLayer()
    path = layer.realPath or layer.identifier
    settings = file_settings(layer.realPath)  # the defaults for a layer in memory
    check = StageCheck(path)
    check.bad_prims.update(composition_errors(stage))
    try:
        mesh = load_stage(stage, path, UsdOptions(time), bad_prims=check.bad_prims)
    except SkippedFile:
        return check
    except MeshError as error:
        check.error = error.reason
        return check
    report = mesh_report(path, mesh, settings)
    check.notes = report.notes
    check.reported_at = {prim: prim for prim in mesh.group_names}
    check.reported_at.update({prim: entry["prim"] for entry in report.shared for prim in entry["prims"]})
    for finding in file_findings(report)[0]:
        check.findings.setdefault(finding.prim or finding.group, []).append(finding)
    return check


def composition_errors(stage) -> dict[str, str]:
    """Prim path -> what composing it failed on (a reference, payload or sublayer that cannot be
    opened, ...), the first error of each prim, on one line."""
    errors: dict[str, str] = {}
    for error in stage.GetCompositionErrors():
        errors.setdefault(str(error.rootSite.path), " ".join(str(error).split()))
    return errors


_checks: dict[tuple, tuple[StageCheck, object]] = {}
#: A validation context may call validators from several threads: one of them checks a stage.
_checking = threading.Lock()


def cached_check(stage, time: float | None = None) -> StageCheck:
    """:func:`check_stage`, made once per stage and time until the stage changes."""
    from pxr import Tf, Usd

    key = (hash(stage), stage.GetRootLayer().identifier, time)
    with _checking:
        if key not in _checks:
            while len(_checks) >= KEPT_STAGES:
                _checks.pop(next(iter(_checks)))
            listener = Tf.Notice.Register(Usd.Notice.ObjectsChanged, lambda notice, sender: _checks.pop(key, None),
                                          stage)
            _checks[key] = check_stage(stage, time), listener
        return _checks[key][0]


@dataclass(eq=False)
class PrimFindings:
    """What one validator family says about one mesh prim.

    ``findings``: the family's findings reported at this prim (none where another prim reports
    for its geometry); ``unreadable``: why the prim (or the stage) cannot be read, said by the
    ``QuadShape`` family only; ``notes``: the stage's notes, said once, by the first family on
    the stage's first mesh prim.
    """

    findings: list[Finding]
    unreadable: str | None = None
    notes: list[str] = field(default_factory=list)


def family_findings(family, prim) -> PrimFindings:
    """:class:`PrimFindings` of ``family`` (:class:`affinity.usd.families.Family`) on ``prim``."""
    from .families import families, unreadable_family

    check = cached_check(prim.GetStage())
    path = str(prim.GetPath())
    said = PrimFindings([])
    if family.name == families()[0].name and path == next(iter(check.reported_at), None):
        said.notes = check.notes
    if family.name == unreadable_family() and (check.error or path in check.bad_prims):
        said.unreadable = check.error or check.bad_prims[path]
    if check.reported_at.get(path) == path:
        said.findings = [f for f in check.findings.get(path, []) if f.code in family.codes]
    return said


def finding_message(f: Finding) -> str:
    """``/prim face F: CODE name: message (value vs threshold unit)`` and, for geometry several prims
    reference, where it is authored and who references it: a line of ``affinity check`` without the path."""
    from ..output import authored_where, describe, face_label, shared_fields

    return f"{face_label(f) or f.prim or f.group}: {f.code} {f.name}: {describe(f)}{authored_where(shared_fields(f))}"


def exception_reason(error: Exception) -> str:
    """An unexpected exception in a validator as one line (a ``Tf.ErrorException``'s first message)."""
    from pxr import Tf

    from ..loaders.usd import pxr_reason

    return pxr_reason(error) if isinstance(error, Tf.ErrorException) else f"{type(error).__name__}: {error}"
