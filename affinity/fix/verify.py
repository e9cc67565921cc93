"""Re-check a fix: lint the fixed mesh in memory as ``affinity check`` lints a file, and compare.

The fixed mesh (:attr:`affinity.fix.plan.FixPlan.refined`) is linted with the fix's settings by
the check's own calls (:func:`affinity.lint.lint_mesh`, then :func:`affinity.findings.settle`
with the file's inline ignores carried to the faces that replace the silenced ones). Two things
are read from it, each on the input's faces (a new face counts for the face it replaces):

* the faces a scored rule (Q101-Q103) still flags at the fix level, other than those the plan
  already leaves: the prediction missed them (``still-flagged``);
* findings of every other rule at warning or above on new faces whose input face had no finding
  of that rule, or that a neighbour cut to meet a refinement (a transition face) had once and its
  pieces have more than once: a fix that adds them is not written unless allowed
  (``--allow-new-findings``). The pieces of a refined quad may keep its own finding (a bent quad
  refined under ``--refine-nonplanar``).
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh


def checked(mesh: Mesh, fix, inline) -> list:
    """The settled findings of ``mesh`` under the fix's lint settings: check's path (module docstring)."""
    from ..findings import settle
    from ..lint import lint_mesh

    return settle(lint_mesh(mesh, fix.lint), fix.lint, list(mesh.group_names), inline)


def verify(mesh: Mesh, plan, fix, baseline: dict) -> tuple[np.ndarray, list[dict]]:
    """Re-check ``plan.refined`` (module docstring).

    Parameters
    ----------
    baseline : code -> (k,) int64 the input faces each rule flags (:func:`flagged_by_rule` of the input)

    Returns
    -------
    flagged : (s,) int64 input faces, ascending, whose faces in the result a scored rule flags at the fix
        level, the plan's left faces excepted
    new : ``{"code": CODE, "face": F}`` per input face F whose new faces have a finding of rule CODE (at
        warning or above) that F had not, or more than one where F is a transition face that had it
    """
    from ..lint import scored_codes
    from .plan import LEVEL_ORDER

    refined = plan.refined
    source = refined.source
    inline = [(codes, np.flatnonzero(np.isin(source, faces))) for codes, faces in fix.inline]
    lowest = LEVEL_ORDER[LEVEL_ORDER.index(fix.level):]
    flagged, new, scored = [], [], scored_codes()
    for h in checked(refined.mesh, fix, inline):
        on_face = h.faces >= 0
        faces, levels = h.faces[on_face], h.levels()[on_face]
        if h.code in scored:
            flagged.append(source[faces[np.isin(levels, lowest)]])
            continue
        added = faces[refined.added[faces] & np.isin(levels, ("warning", "error"))]
        replaced, pieces = np.unique(source[added], return_counts=True)
        had = np.isin(replaced, baseline.get(h.code, np.zeros(0, np.int64)))
        fresh = replaced[~had | ((pieces > 1) & np.isin(replaced, plan.transition_faces))]
        new += [{"code": h.code, "face": int(face)} for face in fresh.tolist()]
    found = np.unique(np.concatenate(flagged or [np.zeros(0, np.int64)]))
    return np.setdiff1d(found, plan.left_faces), new


def flagged_by_rule(mesh: Mesh, fix) -> dict:
    """code -> (k,) int64 the faces of ``mesh`` each rule flags at any level, the check's way."""
    return {h.code: np.unique(h.faces) for h in checked(mesh, fix, fix.inline)}
