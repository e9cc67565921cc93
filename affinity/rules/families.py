"""The validator families (:data:`.registry.FAMILIES`): one UsdValidation validator and one NVIDIA rule each
(:mod:`affinity.usd.families`), in this order; every rule names its family (:attr:`.registry.Rule.family`)."""

from .registry import register_family

UV_AFFINITY = register_family("UvAffinity", "texture coordinates that are not an affine image of the quad (a crease "
                                            "along the split diagonal), in texels.")
COLOR_AFFINITY = register_family("ColorAffinity", "vertex colours that are not an affine image of the quad, in 1/255 "
                                                  "steps.")
NORMAL_AFFINITY = register_family("NormalAffinity", "normals that are not an affine image of the quad, in degrees.")
QUAD_SHAPE = register_family("QuadShape", "degenerate, nonplanar, concave and bow-tie quads, meshes without faces, "
                                          "missing resources.")
UV_LAYOUT = register_family("UvLayout", "quads with no area in texture space, mirrored against the surface, or "
                                        "whose texture drifts under subdivision.")
