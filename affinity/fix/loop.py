"""``plan_fix``: plan -> apply -> verify, until the re-check agrees with the plan.

The candidates are chosen and their levels found once (:func:`affinity.fix.plan.candidates`), cut down to
the output budget (:mod:`affinity.fix.budget`); then each round builds the result
(:func:`affinity.fix.apply.build`) and re-checks it (:mod:`affinity.fix.verify`). A refined quad the
re-check still flags is left ``still-flagged`` (one whose pieces add another rule's finding is left with
that rule's reason), a neighbour whose cut is flagged is kept as it was, and the rest is built again: what
is written is what was checked.
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh
from .apply import build
from .budget import estimated_bytes, within_budget
from .layout import MAX_LEVEL, layout
from .plan import LEVEL_ORDER, Candidates, FixPlan, FixSettings, candidates, left_by_rule, readings
from .twins import readings_from_twins, twin_faces
from .verify import flagged_by_rule, verify


def plan_fix(mesh: Mesh, fix: FixSettings | None = None) -> FixPlan:
    """Decide which flagged quads of ``mesh`` to refine and how far, build the result and re-check it:
    plan -> apply -> verify (:mod:`affinity.fix.verify`), the faces the re-check still flags left as they
    were and the rest re-built, up to ``fix.verify_rounds`` times. The plan holds the result it checked."""
    fix = fix or FixSettings()
    if fix.level not in LEVEL_ORDER:
        raise ValueError(f"fix level must be one of {', '.join(LEVEL_ORDER)}; got {fix.level!r}")
    if not 1 <= fix.max_refine <= MAX_LEVEL:
        raise ValueError(f"max_refine must be from 1 to {MAX_LEVEL}; got {fix.max_refine}")
    found = candidates(mesh, fix)
    baseline = None
    reasons = found.reasons.copy()
    within_budget(mesh, found, reasons, fix)
    still = np.zeros(0, dtype=np.int64)
    quiet = np.zeros(0, dtype=np.int64)  # faces cut beside a refinement whose pieces the re-check flagged
    for _ in range(max(fix.verify_rounds, 1)):
        plan = _plan(mesh, found, reasons, np.union1d(found.uncut, quiet), fix)
        if plan.empty:  # nothing refined: the result is the input, as checked
            flagged = np.zeros(0, dtype=np.int64)
            break
        baseline = flagged_by_rule(mesh, fix) if baseline is None else baseline
        flagged, new = verify(mesh, plan, fix, baseline)
        plan.new_findings = new
        adding = np.array(sorted({d["face"] for d in new}), dtype=np.int64)
        if len(flagged) == 0 and len(adding) == 0:
            break
        still = np.union1d(still, flagged)
        earlier = reasons.copy()
        refined_now = reasons == ""
        leaving = left_by_rule()
        for d in new:  # a refined quad whose pieces add a finding is left for that rule's reason
            reasons[refined_now & (found.faces == d["face"])] = leaving.get(d["code"], "still-flagged")
        reasons[np.isin(found.faces, flagged) & refined_now] = "still-flagged"
        cut = np.intersect1d(np.union1d(flagged, adding), plan.transition_faces)
        if (reasons == earlier).all() and np.isin(cut, quiet).all():  # nothing left to change
            break
        quiet = np.union1d(quiet, cut)
    plan.still_flagged = np.intersect1d(still, plan.left_faces)
    missed = np.setdiff1d(flagged, plan.left_faces)
    if len(missed):  # the last round still flags faces it cut: listed, though their lines are gone
        plan.left_faces = np.concatenate([plan.left_faces, missed])
        plan.left_reasons = np.concatenate([plan.left_reasons, np.full(len(missed), "still-flagged")])
        order = np.argsort(plan.left_faces, kind="stable")
        plan.left_faces, plan.left_reasons = plan.left_faces[order], plan.left_reasons[order]
        plan.still_flagged = np.union1d(plan.still_flagged, missed)
    return plan


def _plan(mesh: Mesh, found: Candidates, reasons: np.ndarray, uncut: np.ndarray, fix: FixSettings) -> FixPlan:
    """The plan of the candidates ``found`` with ``reasons`` (K,) ("" refine), built (``FixPlan.refined``)."""
    refine = reasons == ""
    refine_faces, refine_n = found.faces[refine], found.need[refine]
    frozen = np.union1d(found.faces[~refine], uncut)
    placed = layout(mesh, refine_faces, refine_n, frozen)
    refined = build(mesh, placed)
    codes, before, after, units = readings(mesh, refine_faces, refine_n, found.scored, fix)
    twins = twin_faces(mesh)
    if twins is not None:  # a face refined for its twins' sake reads as they do
        codes, before, after, units = readings_from_twins(twins[refine_faces], codes, before, after, units)
    added = refined.mesh.n_faces - mesh.n_faces
    left = ~refine
    return FixPlan(refine_faces, refine_n, codes, before, after, units, found.faces[left],
                   reasons[left].astype(str), placed.transition_faces, added, fix.max_faces_added,
                   estimated_bytes(mesh, added), frozen, refined=refined)
