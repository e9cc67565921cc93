"""``affinity fix``: refine the quads the affinity rules flag until the crease is gone, crack-free.

The in-memory API (stable; the CLI, the Blender add-on and the USD validators' fixer call it)::

    from affinity.fix import FixSettings, plan_fix, apply_fix

    plan = plan_fix(mesh, FixSettings(level="warning", max_refine=8))   # -> FixPlan
    fixed = apply_fix(mesh, plan)                                       # -> Mesh

:func:`plan_fix` lints ``mesh`` with ``FixSettings.lint`` and picks every quad a scored rule
(Q101-Q103) flags at or above ``FixSettings.level``; each gets the smallest level n
(n x n pieces on its own bilinear surface) at which the rule no longer flags any piece,
up to ``max_refine``. Quads needing more, and degenerate, bow-tie, nonplanar or
uv-degenerate quads, are listed in ``plan.left_faces`` / ``plan.left_reasons``.
``FixSettings.faces`` restricts the refinement to some faces (an editor's selection).

:func:`apply_fix` returns the fixed mesh: the input's vertex, texture-coordinate and normal
tables with new entries appended (no index moves), the faces not touched in file order,
then the pieces of the refined quads and the transition faces that replace each
neighbour sharing a split edge (no T-junction). :func:`refine_mesh` gives the same mesh
with the map from its faces to the input's, which the writers use.
"""

from .apply import Refined, apply_fix, refine_mesh
from .plan import REASONS, FixPlan, FixSettings, plan_fix

__all__ = ["REASONS", "FixPlan", "FixSettings", "Refined", "apply_fix", "plan_fix", "refine_mesh"]
