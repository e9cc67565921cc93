"""Uniform subdivision of a polygon mesh, in NumPy: Catmull-Clark (and bilinear) refinement with creases,
corners, holes, the three boundary rules and the six face-varying linear-interpolation rules, as OpenSubdiv's
Far refines them (:mod:`.refine`); a refined face remembers its base face, so what is measured on the refined
mesh is reported on the face the file wrote.
"""

from .refine import BOUNDARY_RULES, SCHEMES, Refined, Scheme, refine_uniform

__all__ = ["BOUNDARY_RULES", "SCHEMES", "Refined", "Scheme", "refine_uniform"]
