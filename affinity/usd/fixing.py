"""The validators' fixer: ``affinity fix``'s refinement of a prim, written to an edit target.

The prims of a finding (every prim that references a shared geometry layer) are read
together as ``affinity check`` reads them, :func:`affinity.fix.plan_fix` picks the quads
the finding's rule flags at the warning level or above (the fix's default), alike on prims
that compose one authored mesh, and :func:`affinity.fix.refine_mesh` refines them
crack-free. The result goes into the edit target's layer, at the paths the edit target maps
the prims to, by the writer of ``affinity fix``'s override layers
(:func:`affinity.fix.usdlayer.write_refined`: shared geometry written once): the layers below
it are not touched, and primvars or topology indices that no longer match the new faces are
blocked there.
"""

from __future__ import annotations

import threading
from dataclasses import replace

#: Plans kept, at most: the fixer is asked whether it can apply, then applies, once per error (many errors share
#: a plan: each finding of one mesh is an error).
KEPT_PLANS = 16
_plans: dict = {}
_planning = threading.Lock()


def refine_plan(stage, prim_paths: list[str], code: str):
    """``(mesh, plan)``: the prims ``prim_paths`` read together (world space, earliest time), and the plan that
    refines the quads rule ``code`` flags, with the settings that govern the stage's root layer. Prims that
    compose one authored mesh are planned alike (:func:`affinity.fix.twins.twin_faces`). Kept until the stage
    changes (``Usd.Notice.ObjectsChanged``), so the errors of one mesh plan it once; the plan is None where
    :func:`refine_prims` has just written it."""
    key = (hash(stage), stage.GetRootLayer().identifier, tuple(prim_paths), code)
    with _planning:
        if key not in _plans:
            _keep(stage, key, _planned(stage, prim_paths, code))
        return _plans[key][0]


def _keep(stage, key: tuple, planned) -> None:
    """Keep ``planned`` under ``key`` until ``stage`` changes (the oldest plan makes room)."""
    from pxr import Tf, Usd

    while len(_plans) >= KEPT_PLANS:
        _plans.pop(next(iter(_plans)))
    listener = Tf.Notice.Register(Usd.Notice.ObjectsChanged, lambda notice, sender: _plans.pop(key, None), stage)
    _plans[key] = planned, listener


def _planned(stage, prim_paths: list[str], code: str):
    from ..config import file_settings
    from ..fix import FixSettings, plan_fix
    from ..loaders.usd import load_stage

    layer = stage.GetRootLayer()
    settings = replace(file_settings(layer.realPath), select=[code], ignore=[])
    mesh = load_stage(stage, layer.realPath or layer.identifier, prim_paths=list(prim_paths))
    return mesh, plan_fix(mesh, FixSettings(lint=settings))


def can_refine(stage, prim_paths: list[str], code: str) -> bool:
    """Whether the fixer has something to refine on some prim of ``prim_paths``."""
    plan = refine_plan(stage, prim_paths, code)[1]
    return plan is not None and not plan.empty


def refine_prims(stage, prim_paths: list[str], code: str, edit_target) -> bool:
    """Write the refinement of the prims ``prim_paths`` for rule ``code`` through ``edit_target``, as ``affinity
    fix`` writes its layer (:func:`affinity.fix.usdlayer.write_refined`: shared geometry once). The other errors
    of the same prims and rule are fixed by it: their plan is kept empty until the stage changes again."""
    from ..fix import refine_mesh
    from ..fix.usdlayer import write_refined

    mesh, plan = refine_plan(stage, prim_paths, code)
    if plan is not None and not plan.empty:
        write_refined(edit_target.GetLayer(), stage, mesh, refine_mesh(mesh, plan), edit_target.MapToSpecPath)
        with _planning:
            _keep(stage, (hash(stage), stage.GetRootLayer().identifier, tuple(prim_paths), code),
                  (mesh, None))  # None: refined already
    return True
