"""The validators' fixer: ``affinity fix``'s refinement of a prim, written to an edit target.

For each prim of a finding (every prim that references a shared geometry layer),
the prim is read in its own space, :func:`affinity.fix.plan_fix` picks the quads the
finding's rule flags at the warning level or above (the fix's default), and
:func:`affinity.fix.apply_fix` refines them crack-free; :mod:`affinity.usd.author`
writes the result into the prim through the edit target (an opinion in that layer:
the layers below it are not touched). The plan is made in the prim's own space; the
affinity readings do not change under the affine map to world space.
"""

from __future__ import annotations

from dataclasses import replace


def refine_plan(stage, prim_path: str, code: str, time=None):
    """``(mesh, plan, uv_name)`` for refining the quads rule ``code`` flags on the prim at ``prim_path``,
    with the settings that govern the stage's root layer; ``(None, reason, None)`` when the prim's
    geometry cannot be rewritten (:func:`affinity.usd.author.cannot_author`)."""
    from pxr import Usd

    from ..config import file_settings
    from ..fix import FixSettings, plan_fix
    from ..loaders.usd import UsdOptions, load_stage, uv_primvar_name
    from .author import cannot_author

    usd_time = Usd.TimeCode.EarliestTime() if time is None else Usd.TimeCode(time)
    prim = stage.GetPrimAtPath(prim_path)
    uv_name = uv_primvar_name(prim, usd_time)
    reason = cannot_author(prim, usd_time, uv_name)
    if reason is not None:
        return None, reason, None
    settings = file_settings(stage.GetRootLayer().realPath)
    layer = stage.GetRootLayer()
    mesh = load_stage(stage, layer.realPath or layer.identifier, UsdOptions(time), [prim_path], world=False)
    return mesh, plan_fix(mesh, FixSettings(lint=replace(settings, select=[code], ignore=[]))), uv_name


def can_refine(stage, prim_paths: list[str], code: str) -> bool:
    """Whether the fixer has something to refine on some prim of ``prim_paths``, and may write it."""
    plans = [refine_plan(stage, path, code)[:2] for path in prim_paths]
    return all(mesh is not None for mesh, _ in plans) and any(not plan.empty for _, plan in plans)


def refine_prims(stage, prim_paths: list[str], code: str, edit_target) -> bool:
    """Write the refinement of every prim of ``prim_paths`` for rule ``code`` to ``edit_target``;
    False (nothing written) when some prim's geometry cannot be rewritten."""
    from pxr import Usd

    from ..fix import apply_fix
    from .author import author_mesh

    plans = [(path, *refine_plan(stage, path, code)) for path in prim_paths]
    if any(mesh is None for _, mesh, _, _ in plans):
        return False
    for path, mesh, plan, uv_name in plans:
        if not plan.empty:
            author_mesh(stage, path, apply_fix(mesh, plan), edit_target, Usd.TimeCode.EarliestTime(), uv_name)
    return True
