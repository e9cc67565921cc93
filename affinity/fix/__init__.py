"""``affinity fix``: refine the quads the affinity rules flag until the crease is gone, with quads only.

The in-memory API (stable; the CLI, the Blender add-on and the USD validators' fixer call it)::

    from affinity.fix import FixSettings, plan_fix, apply_fix

    plan = plan_fix(mesh, FixSettings(level="warning", max_refine=9))   # -> FixPlan
    fixed = apply_fix(mesh, plan)                                       # -> Mesh

:func:`plan_fix` lints ``mesh`` with ``FixSettings.lint`` and picks every quad a scored rule
(Q101-Q103) flags at or above ``FixSettings.level``; each gets the smallest odd level n
(n x n pieces on its own bilinear surface) at which the rule no longer flags any piece, up
to the cap. Quads needing more, degenerate, bow-tie, nonplanar or uv-degenerate quads, what
the output budget does not reach and what the re-check still flags are listed in
``plan.left_faces`` / ``plan.left_reasons``, and are never cut. The plan is built and
re-checked as ``affinity check`` would check it (plan -> apply -> verify); the plan holds
the result (``plan.refined``). ``FixSettings.faces`` restricts the refinement to some faces
(an editor's selection).

:func:`apply_fix` returns the fixed mesh: the input's vertex, texture-coordinate and normal
tables with new entries appended (no index moves), the faces not touched in file order,
then the quads that replace each refined quad and each neighbour sharing a split edge (no
T-junction, no triangle: a neighbour that is not a quad keeps its corners and gains the
edge's points). :func:`refine_mesh` gives the same mesh with the map from its faces to the
input's, which the writers use.
"""

from .apply import Refined, apply_fix, refine_mesh
from .loop import plan_fix
from .plan import REASONS, FixPlan, FixSettings

__all__ = ["REASONS", "FixPlan", "FixSettings", "Refined", "apply_fix", "plan_fix", "refine_mesh"]
