"""A mesh and a view in, an image out: framing, the renderer's quads, routing, shading, textures, PNG.

- :mod:`.drawing`: ``render_mesh(mesh, RenderOptions) -> RenderResult``, the one entry point;
- :mod:`.framing`: cameras and up axes when the user names none;
- :mod:`.faces`: a mesh's faces as sets (corners, centroids, areas, neighbours, sub-meshes);
- :mod:`.closeup`: a close-up of a place: framing, panels and error map, with its tuning constants;
- :mod:`.quads`: the mesh as the renderer's quads (triangles and n-gons fanned);
- :mod:`.routing`: the hybrid's per-quad choice between ``split`` and ``mvc``;
- :mod:`.shading`: per-corner inputs, pixel colours, the shared palette;
- :mod:`.texture`, :mod:`.png`, :mod:`.flat`: images in and out, flat face-id pictures.

The pyvista scene of ``affinity view`` and the report's overview is ``affinity.view``, a layer above.

``render`` (the rasterizer) knows nothing of meshes; this package is where meshes
meet it. Heavy imports (``render``, Pillow) happen inside the functions. The names
below are the package's public API: the layers above use these, not its modules.
"""

from .closeup import CLOSEUP_SIZE, Closeup, CloseupView, closeup
from .drawing import RenderOptions, RenderResult, over_render_budget, render_mesh
from .faces import face_centroids, face_vertices
from .flat import face_ids
from .framing import UP_AXES, overview_camera, up_axis_of, used_points
from .png import png_bytes, to_pixels
from .quads import render_corners
from .routing import MVC, SPLIT
from .shading import FLAG_COLOUR, OVERLAY_TINT, flat_normals
from .texture import TextureError, checker, painted_texture

__all__ = ["CLOSEUP_SIZE", "FLAG_COLOUR", "MVC", "OVERLAY_TINT", "SPLIT", "UP_AXES", "Closeup", "CloseupView",
           "RenderOptions", "RenderResult", "TextureError", "checker", "closeup", "face_centroids", "face_ids",
           "face_vertices", "flat_normals", "over_render_budget", "overview_camera", "painted_texture", "png_bytes",
           "render_corners", "render_mesh", "to_pixels", "up_axis_of", "used_points"]
