"""A NumPy quad rasterizer: clip-space quads in, images out.

Knows nothing of meshes or files. ``rasterize_quads`` draws quads given by
their clip-space corners with one of several attribute interpolation methods
(``split``, ``mvc``, ``bilinear``, ``projective``, the ``exact`` ray /
bilinear-patch reference, or one per quad: the hybrid); ``render.coords``
holds the quad coordinate functions (``mean_value``, ``inverse_bilinear``),
``render.patch`` the ray / patch intersection and ``render.camera`` the
view/projection matrices that take points to clip space.
"""

from render import camera, coords, patch
from render.camera import (
    Camera,
    frame_bounds,
    look_at,
    orthographic,
    perspective,
    to_clip,
)
from render.frame import Frame
from render.raster import rasterize_quads

__all__ = [
    "Camera",
    "Frame",
    "camera",
    "coords",
    "frame_bounds",
    "look_at",
    "orthographic",
    "patch",
    "perspective",
    "rasterize_quads",
    "to_clip",
]
