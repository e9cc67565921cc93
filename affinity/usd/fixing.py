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

from dataclasses import replace


def refine_plan(stage, prim_paths: list[str], code: str):
    """``(mesh, plan)``: the prims ``prim_paths`` read together (world space, earliest time), and the plan that
    refines the quads rule ``code`` flags, with the settings that govern the stage's root layer. Prims that
    compose one authored mesh are planned alike (:func:`affinity.fix.twins.twin_faces`)."""
    from ..config import file_settings
    from ..fix import FixSettings, plan_fix
    from ..loaders.usd import load_stage

    layer = stage.GetRootLayer()
    settings = replace(file_settings(layer.realPath), select=[code], ignore=[])
    mesh = load_stage(stage, layer.realPath or layer.identifier, prim_paths=list(prim_paths))
    return mesh, plan_fix(mesh, FixSettings(lint=settings))


def can_refine(stage, prim_paths: list[str], code: str) -> bool:
    """Whether the fixer has something to refine on some prim of ``prim_paths``."""
    return not refine_plan(stage, prim_paths, code)[1].empty


def refine_prims(stage, prim_paths: list[str], code: str, edit_target) -> bool:
    """Write the refinement of the prims ``prim_paths`` for rule ``code`` through ``edit_target``, as ``affinity
    fix`` writes its layer (:func:`affinity.fix.usdlayer.write_refined`: shared geometry once)."""
    from ..fix import refine_mesh
    from ..fix.usdlayer import write_refined

    mesh, plan = refine_plan(stage, prim_paths, code)
    if not plan.empty:
        write_refined(edit_target.GetLayer(), stage, mesh, refine_mesh(mesh, plan), edit_target.MapToSpecPath)
    return True
