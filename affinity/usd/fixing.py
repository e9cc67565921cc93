"""The validators' fixer: ``affinity fix``'s refinement of a prim, written to an edit target.

For each prim of a finding (every prim that references a shared geometry layer), the
prim is read as ``affinity check`` reads it, :func:`affinity.fix.plan_fix` picks the
quads the finding's rule flags at the warning level or above (the fix's default) and
:func:`affinity.fix.refine_mesh` refines them crack-free. The result goes into the edit
target's layer, at the path the edit target maps the prim to, by the writer of ``affinity
fix``'s override layers (:func:`affinity.fix.usdlayer.override_prim`): the layers below it
are not touched, and primvars or topology indices that no longer match the new faces
are blocked there.
"""

from __future__ import annotations

from dataclasses import replace


def refine_plan(stage, prim_path: str, code: str):
    """``(mesh, plan)``: the prim at ``prim_path`` (world space, earliest time) and the plan that refines
    the quads rule ``code`` flags, with the settings that govern the stage's root layer."""
    from ..config import file_settings
    from ..fix import FixSettings, plan_fix
    from ..loaders.usd import load_stage

    layer = stage.GetRootLayer()
    settings = replace(file_settings(layer.realPath), select=[code], ignore=[])
    mesh = load_stage(stage, layer.realPath or layer.identifier, prim_paths=[prim_path])
    return mesh, plan_fix(mesh, FixSettings(lint=settings))


def can_refine(stage, prim_paths: list[str], code: str) -> bool:
    """Whether the fixer has something to refine on some prim of ``prim_paths``."""
    return any(not refine_plan(stage, path, code)[1].empty for path in prim_paths)


def refine_prims(stage, prim_paths: list[str], code: str, edit_target) -> bool:
    """Write the refinement of every prim of ``prim_paths`` for rule ``code`` through ``edit_target``."""
    from pxr import Usd, UsdGeom

    from ..fix import refine_mesh
    from ..fix.usdlayer import override_prim

    time = Usd.TimeCode.EarliestTime()
    for path in prim_paths:
        mesh, plan = refine_plan(stage, path, code)
        if plan.empty:
            continue
        prim = stage.GetPrimAtPath(path)
        override_prim(edit_target.GetLayer(), edit_target.MapToSpecPath(prim.GetPath()), prim,
                      refine_mesh(mesh, plan).mesh, 0, time, UsdGeom.XformCache(time))
    return True
